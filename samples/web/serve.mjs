#!/usr/bin/env node
// SPDX-License-Identifier: MIT
// Serves the aggrelod web viewer (this folder, with its node_modules) and one tileset on
// localhost, without any network access:
//
//   node samples/web/serve.mjs --tileset OUTDIR/tiles [--port 8080] [--host 127.0.0.1]
//
// then open http://127.0.0.1:8080/ (the viewer reads ./tileset/tileset.json by default).
// URL layout: /tileset/... -> files of the --tileset folder; everything else -> this folder.
// Only GET and HEAD; paths outside the two folders are refused.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const webDir = path.dirname(fileURLToPath(import.meta.url));

const types = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.json': 'application/json',
  '.glb': 'model/gltf-binary',
  '.gltf': 'model/gltf+json',
  '.png': 'image/png',
  '.map': 'application/json',
  '.wasm': 'application/wasm',
};

/** Resolves a URL path under `root`; null when it would leave `root`. */
function resolveUnder(root, urlPath) {
  const file = path.resolve(root, '.' + path.posix.normalize('/' + urlPath));
  return file === root || file.startsWith(root + path.sep) ? file : null;
}

/**
 * Starts the server; resolves to { server, port, url } once it listens.
 * port 0 picks a free port. `log` (optional) receives one line per request.
 */
export function startServer({ tilesetDir, host = '127.0.0.1', port = 0, log = null }) {
  const tilesetRoot = path.resolve(tilesetDir);
  const server = http.createServer((req, res) => {
    let urlPath;
    try {
      urlPath = decodeURIComponent(new URL(req.url, 'http://localhost').pathname);
    } catch {
      res.writeHead(400).end('bad request');
      return;
    }
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      res.writeHead(405).end('method not allowed');
      return;
    }
    if (urlPath === '/') urlPath = '/index.html';
    const file = urlPath.startsWith('/tileset/')
      ? resolveUnder(tilesetRoot, urlPath.slice('/tileset'.length))
      : resolveUnder(webDir, urlPath);
    fs.stat(file || '', (err, stat) => {
      if (!file || err || !stat.isFile()) {
        if (log) log(`404 ${urlPath}`);
        res.writeHead(404, { 'Content-Type': 'text/plain' }).end(`not found: ${urlPath}`);
        return;
      }
      if (log) log(`200 ${urlPath}`);
      res.writeHead(200, {
        'Content-Type': types[path.extname(file).toLowerCase()] || 'application/octet-stream',
        'Content-Length': stat.size,
        'Cache-Control': 'no-store',
      });
      if (req.method === 'HEAD') res.end();
      else fs.createReadStream(file).pipe(res);
    });
  });
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, host, () => {
      const actualPort = server.address().port;
      resolve({ server, port: actualPort, url: `http://${host}:${actualPort}/` });
    });
  });
}

function usage(message) {
  if (message) console.error(`serve.mjs: ${message}`);
  console.error('usage: node serve.mjs --tileset DIR [--port 8080] [--host 127.0.0.1]');
  process.exit(2);
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  let tilesetDir = null, port = 8080, host = '127.0.0.1';
  for (let i = 0; i < args.length; i++) {
    const value = args[i + 1];
    if (args[i] === '--tileset' && value) { tilesetDir = value; i++; }
    else if (args[i] === '--port' && value) { port = Number(value); i++; }
    else if (args[i] === '--host' && value) { host = value; i++; }
    else usage(`unknown argument ${args[i]}`);
  }
  if (!tilesetDir) usage('--tileset is required');
  if (!fs.existsSync(path.join(tilesetDir, 'tileset.json'))) usage(`${tilesetDir}/tileset.json does not exist`);
  if (!fs.existsSync(path.join(webDir, 'node_modules', '3d-tiles-renderer'))) {
    usage(`${webDir}/node_modules is missing: run "npm ci" there (or .ci/install-deps.sh)`);
  }
  const { url } = await startServer({ tilesetDir, host, port });
  console.log(`aggrelod viewer: ${url}  (tileset ${path.resolve(tilesetDir)}; Ctrl-C stops)`);
  console.log(`  e.g. ${url}?camera=0,5,20&target=0,0,0&errorTarget=16`);
}
