#!/usr/bin/env node
// SPDX-License-Identifier: MIT
// Runs the Khronos glTF validator (npm gltf-validator) on .glb / .gltf files, offline.
//
//   node tests/validator/validate.js FILE.glb [FILE2.gltf ...]
//
// Prints one line per file: "FILE: numErrors=N numWarnings=M numInfos=I", followed by the
// first errors (code, pointer, message). Exit status: 0 when no file has errors, 1 when some
// file has validation errors, 2 on usage errors or unreadable files.
'use strict';

const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const MAX_LISTED = 20;

async function validateFile(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0, // unlimited
    // Resources referenced by a .gltf (buffers, images) are read next to it.
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const resourcePath = path.resolve(path.dirname(file), decodeURIComponent(uri));
        fs.readFile(resourcePath, (err, data) => {
          if (err) reject(err.toString());
          else resolve(new Uint8Array(data));
        });
      }),
  });
  const issues = report.issues;
  console.log(
    `${file}: numErrors=${issues.numErrors} numWarnings=${issues.numWarnings} numInfos=${issues.numInfos}`
  );
  const errors = issues.messages.filter((m) => m.severity === 0);
  for (const m of errors.slice(0, MAX_LISTED)) {
    console.log(`  error ${m.code} at ${m.pointer || '/'}: ${m.message}`);
  }
  if (errors.length > MAX_LISTED) console.log(`  ... ${errors.length - MAX_LISTED} more errors`);
  return issues.numErrors;
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node validate.js FILE.glb [FILE ...]');
    return 2;
  }
  let status = 0;
  for (const file of files) {
    try {
      if ((await validateFile(file)) > 0) status = Math.max(status, 1);
    } catch (err) {
      console.error(`${file}: cannot validate: ${err}`);
      status = 2;
    }
  }
  return status;
}

main().then(
  (status) => process.exit(status),
  (err) => {
    console.error(err);
    process.exit(2);
  }
);
