#!/usr/bin/env node
// SPDX-License-Identifier: AGPL-3.0-or-later
// The web viewer (samples/web) in a real browser: serves it and a baked tileset on localhost,
// opens it in headless Chromium (driven over the DevTools protocol on a pipe, no extra npm
// package) from a far and a near camera, saves both screenshots and checks that different
// tiles were chosen: far = proxies only (no original object), near = the original object in
// front of the camera (a leaf) among the drawn tiles. Needs no network.
//
//   node tests/web/viewer_chromium_test.mjs --tileset OUTDIR/tiles --out DIR [--chromium PATH]
//
// Writes DIR/far.png, DIR/near.png and DIR/result.json. Exit status 0: passed, 1: failed,
// 2: cannot run (no Chromium, viewer not installed). Prints "viewer test: PASSED" or
// "viewer test: FAILED" last.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Cdp, findChromium } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.resolve(here, '..', '..', 'samples', 'web');
const WIDTH = 800, HEIGHT = 600, FOV = 60, ERROR_TARGET = 16;
const PAGE_TIMEOUT_MS = 20000;
const WATCHDOG_MS = 90000;

function parseArgs() {
  const args = process.argv.slice(2);
  const o = { tileset: null, out: null, chromium: null };
  for (let i = 0; i < args.length; i += 2) {
    const key = args[i].replace(/^--/, '');
    if (!(key in o) || args[i + 1] === undefined) throw new Error(`bad argument ${args[i]}`);
    o[key] = args[i + 1];
  }
  if (!o.tileset || !o.out) throw new Error('usage: --tileset DIR --out DIR [--chromium PATH]');
  return o;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/** Root box centre and radius in the scene's y-up coordinates (tileset is z-up: (x, -z, y)). */
function sceneBounds(tile) {
  const b = tile.boundingVolume.box;
  const center = [b[0], b[2], -b[1]];
  const radius = Math.hypot(b[3] + b[6] + b[9], b[4] + b[7] + b[10], b[5] + b[8] + b[11]);
  return { center, radius, error: tile.geometricError };
}

/** Every leaf with its parent tile. */
function leavesOf(tile, parent = null, out = []) {
  if (!tile.children || tile.children.length === 0) out.push({ leaf: tile, parent });
  else for (const c of tile.children) leavesOf(c, tile, out);
  return out;
}

/** Distance from point p (scene y-up coordinates) to the axis-aligned box of `tile`. */
function distanceToBox(tile, p) {
  const b = tile.boundingVolume.box;
  const center = [b[0], b[2], -b[1]];
  const half = [Math.abs(b[3]), Math.abs(b[11]), Math.abs(b[7])]; // aggrelod boxes are axis-aligned
  return Math.hypot(...[0, 1, 2].map((k) => Math.max(0, Math.abs(p[k] - center[k]) - half[k])));
}

const pixelsPerUnitAtOne = HEIGHT / (2 * Math.tan((FOV * Math.PI) / 360));

/**
 * The leaf for the near view: seen from 3 of its radii, its parent's screen-space error must be
 * well above the target (so the original itself must be drawn); among those, the one farthest
 * from the scene centre (off every axis, so that boxes in the wrong axis convention would put
 * it elsewhere and the viewer would not draw it). Null when no leaf qualifies.
 */
function nearLeaf(root, sceneCenter) {
  const parentOf = new Map();
  (function walk(tile) {
    for (const c of tile.children || []) { parentOf.set(c, tile); walk(c); }
  })(root);
  let best = null, bestDistance = -1;
  for (const { leaf } of leavesOf(root)) {
    // The node to see drawn: the original, or the finest of its per-object LODs whose parent is
    // still too coarse on screen at 3, 2 or 1.5 radii (a fine per-object LOD makes the original
    // itself needless at any distance outside it).
    const bounds = sceneBounds(leaf);
    for (let node = leaf; parentOf.get(node); node = parentOf.get(node)) {
      const parent = parentOf.get(node);
      const radii = [3, 2, 1.5].find((r) => {
        const camera = cameraAt(bounds.center, r * bounds.radius);
        return parent.geometricError * pixelsPerUnitAtOne / Math.max(distanceToBox(parent, camera), 1e-9) >= 1.5 * ERROR_TARGET;
      });
      if (radii !== undefined) {
        const d = Math.hypot(...bounds.center.map((c, k) => c - sceneCenter[k]));
        if (d > bestDistance) {
          // `node` or any finer version of the object (down to the original) counts as drawn:
          // the viewer may refine further when it measures the distance a little differently.
          const versions = [];
          for (let v = leaf; v !== parent; v = parentOf.get(v)) versions.push(v.extras ? v.extras.node : undefined);
          best = { leaf, node, radii, versions };
          bestDistance = d;
        }
        break;
      }
      if (!(node.extras && node.extras.objectLod !== undefined) && node !== leaf) break;  // stop at aggregates
    }
  }
  return best;
}

/** Camera along a fixed oblique direction from `center` at `distance`. */
function cameraAt(center, distance) {
  const d = [1.0, 0.8, 1.2];
  const n = Math.hypot(...d);
  return center.map((c, k) => c + (d[k] / n) * distance);
}

async function loadView(cdp, sessionId, baseUrl, name, camera, target, outDir, consoleLines) {
  const query = `?tileset=./tileset/tileset.json&camera=${camera.join(',')}&target=${target.join(',')}` +
    `&errorTarget=${ERROR_TARGET}&fov=${FOV}`;
  await cdp.send('Page.navigate', { url: baseUrl + query }, sessionId);
  const start = Date.now();
  let state = null;
  while (Date.now() - start < PAGE_TIMEOUT_MS) {
    await sleep(200);
    const r = await cdp.send('Runtime.evaluate',
      { expression: 'JSON.stringify(window.viewerState || null)', returnByValue: true }, sessionId);
    state = r.result && r.result.value ? JSON.parse(r.result.value) : null;
    if (state && (state.settled || state.error)) break;
  }
  const shot = await cdp.send('Page.captureScreenshot', { format: 'png' }, sessionId);
  const png = path.join(outDir, `${name}.png`);
  fs.writeFileSync(png, Buffer.from(shot.data, 'base64'));
  const seconds = ((Date.now() - start) / 1000).toFixed(1);
  if (!state) throw new Error(`${name}: the viewer did not start (console: ${consoleLines.slice(-5).join(' | ')})`);
  if (state.error) throw new Error(`${name}: the viewer reports: ${state.error}`);
  if (!state.settled) throw new Error(`${name}: loading did not settle within ${PAGE_TIMEOUT_MS / 1000} s`);
  console.log(`${name}: camera ${camera.map((v) => v.toFixed(3)).join(',')} -> ${state.visibleTiles.length} tiles ` +
    `(nodes ${state.visibleTiles.map((t) => t.node).join(' ')}) in ${seconds} s; screenshot ${png}`);
  return state;
}

async function run(o) {
  const tilesetFile = path.join(o.tileset, 'tileset.json');
  const tileset = JSON.parse(fs.readFileSync(tilesetFile, 'utf8'));
  if (!fs.existsSync(path.join(webDir, 'node_modules', '3d-tiles-renderer'))) {
    console.error(`${webDir}/node_modules is missing: run .ci/install-deps.sh (npm ci in samples/web)`);
    return 2;
  }
  const chromium = findChromium(o.chromium);
  if (!chromium) {
    console.error('Chromium not found (Debian package chromium; .ci/install-deps.sh installs it)');
    return 2;
  }
  fs.mkdirSync(o.out, { recursive: true });

  // Far: 3 radii of the scene from its centre (the whole scene in view). Near: 3 radii of a
  // leaf (the original object farthest from the centre) from that leaf.
  const scene = sceneBounds(tileset.root);
  const farDistance = 3 * scene.radius;
  const nearPick = nearLeaf(tileset.root, scene.center);
  if (!nearPick) {
    console.log('error: no original object whose parent is coarse enough on screen from 1.5 of its radii');
    return 1;
  }
  const leafTile = nearPick.leaf;
  const leafNode = nearPick.node.extras ? nearPick.node.extras.node : undefined;
  const leaf = sceneBounds(leafTile);
  const nearDistance = nearPick.radii * leaf.radius;
  const views = [
    { name: 'far', camera: cameraAt(scene.center, farDistance), target: scene.center },
    { name: 'near', camera: cameraAt(leaf.center, nearDistance), target: leaf.center },
  ];

  const { startServer } = await import(path.join(webDir, 'serve.mjs'));
  const requests = [];
  const { server, url } = await startServer({ tilesetDir: o.tileset, log: (line) => requests.push(line) });
  const profile = fs.mkdtempSync(path.join(o.out, 'chromium-profile-'));
  const child = spawn(chromium, [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--no-first-run', '--no-default-browser-check', '--disable-extensions', '--mute-audio',
    '--hide-scrollbars', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-dev-shm-usage',
    `--window-size=${WIDTH},${HEIGHT}`, `--user-data-dir=${profile}`, '--remote-debugging-pipe', 'about:blank',
  ], { stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe'] });
  let stderr = '';
  child.stderr.on('data', (d) => { stderr += d.toString(); });
  const exited = new Promise((resolve) => child.on('exit', resolve));
  const cdp = new Cdp(child);
  child.on('exit', (code, signal) => {
    for (const { reject, method } of cdp.pending.values()) {
      reject(new Error(`${method}: Chromium exited (code ${code}, signal ${signal})`));
    }
    cdp.pending.clear();
  });
  child.on('error', (e) => {
    for (const { reject } of cdp.pending.values()) reject(new Error(`cannot start ${chromium}: ${e.message}`));
    cdp.pending.clear();
  });
  const consoleLines = [];
  cdp.listeners.push((m) => {
    if (m.method === 'Runtime.consoleAPICalled') {
      consoleLines.push(m.params.args.map((a) => a.value ?? a.description ?? '').join(' '));
    } else if (m.method === 'Runtime.exceptionThrown') {
      consoleLines.push('exception: ' + (m.params.exceptionDetails.exception?.description || m.params.exceptionDetails.text));
    }
  });

  const states = {};
  try {
    const { targetId } = await cdp.send('Target.createTarget', { url: 'about:blank' });
    const { sessionId } = await cdp.send('Target.attachToTarget', { targetId, flatten: true });
    await cdp.send('Emulation.setDeviceMetricsOverride', { width: WIDTH, height: HEIGHT, deviceScaleFactor: 1, mobile: false }, sessionId);
    await cdp.send('Page.enable', {}, sessionId);
    await cdp.send('Runtime.enable', {}, sessionId);
    for (const v of views) {
      states[v.name] = await loadView(cdp, sessionId, url, v.name, v.camera, v.target, o.out, consoleLines);
    }
    await cdp.send('Browser.close').catch(() => {});
  } catch (e) {
    console.log(`error: ${e.message}`);
    if (consoleLines.length) console.log('browser console:\n  ' + consoleLines.slice(-20).join('\n  '));
    if (stderr.trim()) console.log('chromium stderr (last lines):\n  ' + stderr.trim().split('\n').slice(-10).join('\n  '));
    child.kill('SIGKILL');
    server.close();
    return 1;
  }
  await Promise.race([exited, sleep(5000)]);
  if (child.exitCode === null) child.kill('SIGKILL');
  server.close();
  fs.rmSync(profile, { recursive: true, force: true });

  // The tiles chosen must differ: far = proxies only, near = original objects among them.
  const failures = [];
  const far = states.far.visibleTiles, near = states.near.visibleTiles;
  const farLeaves = far.filter((t) => t.leaf), nearLeaves = near.filter((t) => t.leaf);
  if (far.length === 0) failures.push('far: no tile drawn');
  if (farLeaves.length > 0) failures.push(`far: ${farLeaves.length} original objects drawn (expected proxies only)`);
  if (!near.some((t) => nearPick.versions.includes(t.node))) {
    failures.push(`near: the object in front of the camera (node ${leafNode} or a finer version of it: ` +
      `${nearPick.versions.join(' ')}) is not drawn`);
  }
  const farMinError = Math.min(...far.map((t) => t.geometricError));
  const nearMinError = Math.min(...near.map((t) => t.geometricError));
  if (JSON.stringify(far.map((t) => t.node)) === JSON.stringify(near.map((t) => t.node))) failures.push('same tiles near and far');
  const notServed = requests.filter((r) => r.startsWith('404'));
  if (notServed.length) failures.push(`requests not served: ${notServed.join(', ')}`);
  fs.writeFileSync(path.join(o.out, 'result.json'), JSON.stringify({ views, far, near, failures }, null, 2) + '\n');
  console.log(`near view looks at node ${leafNode}; far: ${far.length} tiles, ${farLeaves.length} originals, min error ${farMinError}; ` +
    `near: ${near.length} tiles, ${nearLeaves.length} originals, min error ${nearMinError}`);
  for (const f of failures) console.log(`failure: ${f}`);
  return failures.length ? 1 : 0;
}

// Whatever hangs (Chromium not answering, a page that never settles), the test ends.
const watchdog = setTimeout(() => {
  console.log(`error: no result after ${WATCHDOG_MS / 1000} s`);
  console.log('viewer test: FAILED');
  process.exit(1);
}, WATCHDOG_MS);
watchdog.unref();

let status;
try {
  status = await run(parseArgs());
} catch (e) {
  console.log(`error: ${e.stack || e.message}`);
  status = 2;
}
console.log(status === 0 ? 'viewer test: PASSED' : 'viewer test: FAILED');
process.exit(status);
