#!/usr/bin/env node
// SPDX-License-Identifier: AGPL-3.0-or-later
// A plain three.js import of the bake's GLB files in a real browser: samples/web/import.html
// loads the input scene, levels.glb, proxies.glb and collision.glb with GLTFLoader alone (no
// aggrelod code, no MSFT_lod support) in headless Chromium and reports what gltf.scene, the
// default scene, holds. Each output must show one level, not all: its visible meshes stand for
// every original object exactly once (extras.source_ids), so nothing overlaps; proxies.glb
// shows the originals themselves (its finest level), the same triangles as the input; every
// drawn mesh of levels.glb and proxies.glb has normals and vertex colours; the files hold more
// (the coarser levels) than they show. Writes DIR/import_<file>.png for each output.
//
//   node tests/web/plain_import_chromium_test.mjs --dir DIR --input SCENE.glb --outputs OUTDIR [--chromium PATH]
//
// DIR is served; SCENE.glb and OUTDIR are relative to it. Prints "plain import test: PASSED"
// or "plain import test: FAILED" last. Exit status 0 passed, 1 failed, 2 cannot run.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { findChromium, startChromium } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.resolve(here, '..', '..', 'samples', 'web');
const WIDTH = 800, HEIGHT = 600;
const PAGE_TIMEOUT_MS = 30000;

function parseArgs() {
  const args = process.argv.slice(2);
  const o = { dir: null, input: null, outputs: null, chromium: null };
  for (let i = 0; i < args.length; i += 2) {
    const key = args[i].replace(/^--/, '');
    if (!(key in o) || args[i + 1] === undefined) throw new Error(`bad argument ${args[i]}`);
    o[key] = args[i + 1];
  }
  if (!o.dir || !o.input || !o.outputs) throw new Error('usage: --dir DIR --input SCENE.glb --outputs OUTDIR [--chromium PATH]');
  return o;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function loadPage(browser, url) {
  const { cdp, sessionId } = browser;
  await cdp.send('Page.navigate', { url }, sessionId);
  const start = Date.now();
  while (Date.now() - start < PAGE_TIMEOUT_MS) {
    await sleep(200);
    const r = await cdp.send('Runtime.evaluate', { expression: 'JSON.stringify(window.importState || null)', returnByValue: true }, sessionId);
    const state = r.result && r.result.value ? JSON.parse(r.result.value) : null;
    if (state && (state.done || state.error)) return state;
  }
  throw new Error(`${url}: the page did not finish within ${PAGE_TIMEOUT_MS / 1000} s`);
}

/** Failures for one output: each object once, nothing else. */
function coverFailures(label, file, objectCount) {
  const failures = [];
  const seen = new Array(objectCount).fill(0);
  for (let i = 0; i < file.sourceIds.length; ++i) {
    const ids = file.sourceIds[i];
    if (!Array.isArray(ids)) { failures.push(`${label}: visible mesh ${file.names[i]} has no extras.source_ids`); continue; }
    for (const id of ids) {
      if (!(id >= 0 && id < objectCount)) failures.push(`${label}: ${file.names[i]} names object ${id}`);
      else seen[id] += 1;
    }
  }
  const twice = seen.filter((n) => n > 1).length, never = seen.filter((n) => n === 0).length;
  if (twice) failures.push(`${label}: ${twice} objects are drawn more than once (levels overlap)`);
  if (never) failures.push(`${label}: ${never} objects are not drawn at all`);
  return failures;
}

async function run(o) {
  if (!fs.existsSync(path.join(webDir, 'node_modules', 'three'))) {
    console.error(`${webDir}/node_modules is missing: run .ci/install-deps.sh (npm ci in samples/web)`);
    return 2;
  }
  const chromium = findChromium(o.chromium);
  if (!chromium) {
    console.error('Chromium not found (Debian package chromium; .ci/install-deps.sh installs it)');
    return 2;
  }
  const names = ['levels.glb', 'proxies.glb', 'collision.glb'];
  const urls = [`./tileset/${o.input}`, ...names.map((n) => `./tileset/${o.outputs}/${n}`)];
  for (const u of urls) {
    if (!fs.existsSync(path.join(o.dir, u.slice('./tileset/'.length)))) {
      console.log(`error: ${u} does not exist under ${o.dir}`);
      return 1;
    }
  }
  const { startServer } = await import(path.join(webDir, 'serve.mjs'));
  const requests = [];
  const { server, url } = await startServer({ tilesetDir: o.dir, log: (line) => requests.push(line) });
  const profile = fs.mkdtempSync(path.join(o.dir, 'chromium-profile-'));
  let browser = null;
  const states = [];
  try {
    browser = await startChromium(chromium, profile, WIDTH, HEIGHT);
    for (let k = 1; k < urls.length; ++k) {
      const state = await loadPage(browser, `${url}import.html?files=${urls.join(',')}&show=${k}`);
      if (state.error) throw new Error(`import.html reports: ${state.error}`);
      const shot = await browser.cdp.send('Page.captureScreenshot', { format: 'png' }, browser.sessionId);
      fs.writeFileSync(path.join(o.dir, `import_${names[k - 1].replace('.glb', '')}.png`), Buffer.from(shot.data, 'base64'));
      states.push(state);
    }
    await browser.cdp.send('Browser.close').catch(() => {});
  } catch (e) {
    console.log(`error: ${e.message}`);
    if (browser && browser.stderr().trim()) console.log('chromium stderr (last lines):\n  ' + browser.stderr().trim().split('\n').slice(-10).join('\n  '));
    if (browser) browser.child.kill('SIGKILL');
    server.close();
    return 1;
  }
  await Promise.race([browser.exited, sleep(5000)]);
  if (browser.child.exitCode === null) browser.child.kill('SIGKILL');
  server.close();
  fs.rmSync(profile, { recursive: true, force: true });

  const [input, levels, proxies, collision] = states[0].files;
  const objectCount = input.visibleMeshes;
  const failures = [];
  for (const [label, f] of [['levels.glb', levels], ['proxies.glb', proxies], ['collision.glb', collision]]) {
    console.log(`${label}: default scene ${f.defaultScene} of ${f.scenes}; drawn ${f.visibleMeshes} meshes, ${f.visibleTriangles} ` +
      `triangles; the file holds ${f.fileMeshes} meshes, ${f.fileTriangles} triangles; extensionsUsed ${JSON.stringify(f.extensionsUsed)}`);
    failures.push(...coverFailures(label, f, objectCount));
    if (!(f.fileTriangles > f.visibleTriangles)) failures.push(`${label}: shows everything it holds (no hidden coarser levels)`);
  }
  console.log(`input: ${input.visibleMeshes} meshes, ${input.visibleTriangles} triangles`);
  if (proxies.visibleTriangles !== input.visibleTriangles) {
    failures.push(`proxies.glb: draws ${proxies.visibleTriangles} triangles, the originals have ${input.visibleTriangles}`);
  }
  const notLod0 = proxies.names.filter((n) => !/_LOD0$/.test(n));
  if (notLod0.length) failures.push(`proxies.glb: drawn meshes not named *_LOD0: ${notLod0.slice(0, 5).join(', ')}`);
  const notLevel0 = levels.names.filter((n) => !/^(level0_group\d+|support_.*)$/.test(n));
  if (notLevel0.length) failures.push(`levels.glb: drawn meshes of another level than 0: ${notLevel0.slice(0, 5).join(', ')}`);
  for (const [label, f] of [['levels.glb', levels], ['proxies.glb', proxies]]) {
    if (f.meshesWithoutNormals) failures.push(`${label}: ${f.meshesWithoutNormals} drawn meshes without normals`);
    if (f.meshesWithoutColors) failures.push(`${label}: ${f.meshesWithoutColors} drawn meshes without vertex colours`);
  }
  if (!levels.extensionsUsed.includes('MSFT_lod') || !proxies.extensionsUsed.includes('MSFT_lod')) failures.push('MSFT_lod not in extensionsUsed');
  const notServed = requests.filter((r) => r.startsWith('404'));
  if (notServed.length) failures.push(`requests not served: ${notServed.join(', ')}`);
  fs.writeFileSync(path.join(o.dir, 'import_result.json'), JSON.stringify({ files: states[0].files, failures }, null, 2) + '\n');
  for (const f of failures) console.log(`failure: ${f}`);
  return failures.length ? 1 : 0;
}

const watchdog = setTimeout(() => {
  console.log('error: no result after 120 s');
  console.log('plain import test: FAILED');
  process.exit(1);
}, 120000);
watchdog.unref();

let status;
try {
  status = await run(parseArgs());
} catch (e) {
  console.log(`error: ${e.stack || e.message}`);
  status = 2;
}
console.log(status === 0 ? 'plain import test: PASSED' : 'plain import test: FAILED');
process.exit(status);
