// SPDX-License-Identifier: AGPL-3.0-or-later
// The one check that the browser tests' tools are installed (Chromium, samples/web's npm
// packages); the browser tests require it as a CTest fixture, so a missing tool is reported
// here once instead of as a failure of every browser test. .ci/install-deps.sh installs them.
//   node tests/web/web_tools_present.mjs [--chromium PATH]
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { findChromium } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const at = process.argv.indexOf('--chromium');
const problems = [];

const chromium = findChromium(at > 0 ? process.argv[at + 1] : null);
if (!chromium) {
  problems.push(`Chromium not found${at > 0 ? ` at ${process.argv[at + 1]}` : ''} (Debian package chromium)`);
} else {
  const version = spawnSync(chromium, ['--version'], { encoding: 'utf8', timeout: 60000 });
  if (version.status !== 0) problems.push(`${chromium} --version failed: ${(version.stderr || version.error || '').toString().trim()}`);
  else console.log(`chromium: ${version.stdout.trim()}`);
}
const modules = path.join(here, '..', '..', 'samples', 'web', 'node_modules');
const pkg = JSON.parse(fs.readFileSync(path.join(here, '..', '..', 'samples', 'web', 'package.json'), 'utf8'));
for (const name of Object.keys(pkg.dependencies || {})) {
  if (!fs.existsSync(path.join(modules, name, 'package.json'))) problems.push(`npm package ${name} is not installed in ${modules}`);
}
for (const p of problems) console.log(`missing: ${p}`);
if (problems.length) console.log('run .ci/install-deps.sh (it installs them), then run the browser tests again');
console.log(`web tools: ${problems.length ? 'MISSING' : 'PRESENT'}`);
process.exit(problems.length ? 1 : 0);
