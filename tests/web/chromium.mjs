// SPDX-License-Identifier: AGPL-3.0-or-later
// Headless Chromium for the web tests: finding the browser and a minimal DevTools-protocol
// client over --remote-debugging-pipe (no extra npm package).
import { spawn } from 'node:child_process';
import fs from 'node:fs';

export function findChromium(explicit) {
  const candidates = explicit ? [explicit] : ['/usr/bin/chromium', '/usr/bin/chromium-browser', '/usr/bin/google-chrome'];
  return candidates.find((c) => fs.existsSync(c)) || null;
}

/** Minimal DevTools-protocol client over --remote-debugging-pipe (fd 3: to Chromium, fd 4: from it). */
export class Cdp {
  constructor(child) {
    this.nextId = 1;
    this.pending = new Map();
    this.listeners = [];
    this.writer = child.stdio[3];
    const failAll = (e) => {
      for (const { reject, method } of this.pending.values()) reject(new Error(`${method}: ${e.message}`));
      this.pending.clear();
    };
    this.writer.on('error', failAll);
    child.stdio[4].on('error', failAll);
    let buffer = '';
    child.stdio[4].on('data', (chunk) => {
      buffer += chunk.toString('utf8');
      let end;
      while ((end = buffer.indexOf('\0')) >= 0) {
        const message = JSON.parse(buffer.slice(0, end));
        buffer = buffer.slice(end + 1);
        if (message.id !== undefined && this.pending.has(message.id)) {
          const { resolve, reject, method } = this.pending.get(message.id);
          this.pending.delete(message.id);
          if (message.error) reject(new Error(`${method}: ${message.error.message}`));
          else resolve(message.result);
        } else if (message.method) {
          for (const l of this.listeners) l(message);
        }
      }
    });
  }

  send(method, params = {}, sessionId = undefined) {
    const id = this.nextId++;
    const message = { id, method, params };
    if (sessionId) message.sessionId = sessionId;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, method });
      this.writer.write(JSON.stringify(message) + '\0');
    });
  }
}

/**
 * Starts headless Chromium (software GL) with a fresh profile in `profileDir`, window
 * width x height, and attaches a page. Resolves to { child, cdp, sessionId, exited, stderr() }.
 */
export async function startChromium(chromium, profileDir, width, height) {
  const child = spawn(chromium, [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--no-first-run', '--no-default-browser-check', '--disable-extensions', '--mute-audio',
    '--hide-scrollbars', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-dev-shm-usage',
    `--window-size=${width},${height}`, `--user-data-dir=${profileDir}`, '--remote-debugging-pipe', 'about:blank',
  ], { stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe'] });
  let stderr = '';
  child.stderr.on('data', (d) => { stderr += d.toString(); });
  const exited = new Promise((resolve) => child.on('exit', resolve));
  const cdp = new Cdp(child);
  child.on('exit', (code, signal) => {
    for (const { reject, method } of cdp.pending.values()) reject(new Error(`${method}: Chromium exited (code ${code}, signal ${signal})`));
    cdp.pending.clear();
  });
  child.on('error', (e) => {
    for (const { reject } of cdp.pending.values()) reject(new Error(`cannot start ${chromium}: ${e.message}`));
    cdp.pending.clear();
  });
  const { targetId } = await cdp.send('Target.createTarget', { url: 'about:blank' });
  const { sessionId } = await cdp.send('Target.attachToTarget', { targetId, flatten: true });
  await cdp.send('Emulation.setDeviceMetricsOverride', { width, height, deviceScaleFactor: 1, mobile: false }, sessionId);
  await cdp.send('Page.enable', {}, sessionId);
  await cdp.send('Runtime.enable', {}, sessionId);
  return { child, cdp, sessionId, exited, stderr: () => stderr };
}
