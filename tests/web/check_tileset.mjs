#!/usr/bin/env node
// SPDX-License-Identifier: AGPL-3.0-or-later
// Checks a 3D Tiles tileset written by `aggrelod bake ... --tiles` (run from CTest through the
// unit tests, see test_tiles_export.cpp):
//
//   node tests/web/check_tileset.mjs OUTDIR/tiles/tileset.json
//
// Structure: asset.version 1.0 or 1.1, the tileset's geometricError >= the root's, a box on
// every tile, refine REPLACE on every tile, geometric errors never larger than the parent's,
// every child box inside its parent box, leaves with error 0 and a content, every content file
// present. Contents: every GLB passes the Khronos glTF validator (tests/validator) with 0 errors.
// Prints "tiles=N contents=M leaves=L depth=D rootError=E tilesetError=T glbErrors=G" and,
// on failure, one line per problem. Exit status 0: all good, 1: problems, 2: cannot run.
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const MAX_LISTED = 30;

function loadValidator() {
  const require = createRequire(path.join(here, '..', 'validator', 'package.json'));
  return require('gltf-validator');
}

/** The 8 corners of a 3D Tiles box [c, a1, a2, a3]. */
function corners(box) {
  const out = [];
  for (const s1 of [-1, 1]) for (const s2 of [-1, 1]) for (const s3 of [-1, 1]) {
    out.push([0, 1, 2].map((k) => box[k] + s1 * box[3 + k] + s2 * box[6 + k] + s3 * box[9 + k]));
  }
  return out;
}

/** True when point p lies in box (relative slack `slack` of each half axis, plus `absolute`). */
function inside(box, p, slack, absolute) {
  for (let a = 0; a < 3; a++) {
    const axis = box.slice(3 + 3 * a, 6 + 3 * a);
    const len2 = axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2];
    const d = (p[0] - box[0]) * axis[0] + (p[1] - box[1]) * axis[1] + (p[2] - box[2]) * axis[2];
    // |d| / |axis| <= |axis|
    if (Math.abs(d) > len2 * (1 + slack) + absolute * Math.sqrt(len2)) return false;
  }
  return true;
}

async function main() {
  const file = process.argv[2];
  if (!file) {
    console.error('usage: node check_tileset.mjs TILESET.json');
    return 2;
  }
  let tileset;
  try {
    tileset = JSON.parse(fs.readFileSync(file, 'utf8'));
  } catch (e) {
    console.error(`${file}: cannot read: ${e.message}`);
    return 2;
  }
  let validator;
  try {
    validator = loadValidator();
  } catch (e) {
    console.error(`gltf-validator is not installed in tests/validator/node_modules (run .ci/install-deps.sh): ${e.message}`);
    return 2;
  }
  const dir = path.dirname(file);
  const problems = [];
  const problem = (where, what) => problems.push(`${where}: ${what}`);

  if (!tileset.asset || !['1.0', '1.1'].includes(tileset.asset.version)) problem('asset', 'version is not "1.0" or "1.1"');
  if (!(typeof tileset.geometricError === 'number' && tileset.geometricError >= 0)) problem('tileset', 'no geometricError >= 0');
  if (!tileset.root) {
    problem('tileset', 'no root tile');
    for (const p of problems) console.log(p);
    return 1;
  }
  if (tileset.root.geometricError > tileset.geometricError) {
    problem('root', `geometricError ${tileset.root.geometricError} exceeds the tileset's ${tileset.geometricError}`);
  }
  const rootBox = tileset.root.boundingVolume && tileset.root.boundingVolume.box;
  let scale = 1;
  if (Array.isArray(rootBox) && rootBox.length === 12) {
    scale = Math.hypot(...rootBox.slice(3));
  }
  const absolute = 1e-9 * scale; // double rounding of the printed boxes

  const contents = [];
  let tiles = 0, leaves = 0, depth = 0;
  const walk = (tile, where, parent, level) => {
    tiles++;
    depth = Math.max(depth, level + 1);
    const box = tile.boundingVolume && tile.boundingVolume.box;
    if (!Array.isArray(box) || box.length !== 12 || !box.every(Number.isFinite)) {
      problem(where, 'boundingVolume.box is not 12 finite numbers');
    }
    if (!(typeof tile.geometricError === 'number' && Number.isFinite(tile.geometricError) && tile.geometricError >= 0)) {
      problem(where, 'geometricError is not a finite number >= 0');
    }
    if (tile.refine !== 'REPLACE') problem(where, `refine is ${JSON.stringify(tile.refine)}, not "REPLACE"`);
    if (parent) {
      if (tile.geometricError > parent.geometricError) {
        problem(where, `geometricError ${tile.geometricError} exceeds its parent's ${parent.geometricError}`);
      }
      const parentBox = parent.boundingVolume && parent.boundingVolume.box;
      if (Array.isArray(box) && Array.isArray(parentBox) && !corners(box).every((c) => inside(parentBox, c, 1e-12, absolute))) {
        problem(where, 'bounding box is not inside its parent\'s');
      }
    }
    const children = tile.children || [];
    if (children.length === 0) {
      leaves++;
      if (tile.geometricError !== 0) problem(where, `leaf with geometricError ${tile.geometricError} (must be 0)`);
      if (!tile.content) problem(where, 'leaf without content');
    }
    if (tile.content) {
      const uri = tile.content.uri;
      if (typeof uri !== 'string' || !uri.toLowerCase().endsWith('.glb')) {
        problem(where, `content.uri ${JSON.stringify(uri)} is not a .glb`);
      } else if (!fs.existsSync(path.join(dir, uri))) {
        problem(where, `content ${uri} does not exist`);
      } else {
        contents.push({ where, uri });
      }
    }
    children.forEach((c, i) => walk(c, `${where}.children[${i}]`, tile, level + 1));
  };
  walk(tileset.root, 'root', null, 0);

  let glbErrors = 0;
  for (const { where, uri } of contents) {
    const bytes = new Uint8Array(fs.readFileSync(path.join(dir, uri)));
    const report = await validator.validateBytes(bytes, { uri, maxIssues: 0 });
    if (report.issues.numErrors > 0) {
      glbErrors += report.issues.numErrors;
      const first = report.issues.messages.find((m) => m.severity === 0);
      problem(`${where} ${uri}`, `${report.issues.numErrors} glTF validator errors, first: ${first.code} at ${first.pointer}: ${first.message}`);
    }
  }

  console.log(`tiles=${tiles} contents=${contents.length} leaves=${leaves} depth=${depth} ` +
    `rootError=${tileset.root.geometricError} tilesetError=${tileset.geometricError} glbErrors=${glbErrors}`);
  for (const p of problems.slice(0, MAX_LISTED)) console.log(`problem: ${p}`);
  if (problems.length > MAX_LISTED) console.log(`... ${problems.length - MAX_LISTED} more problems`);
  return problems.length === 0 ? 0 : 1;
}

main().then((status) => process.exit(status), (e) => { console.error(e); process.exit(2); });
