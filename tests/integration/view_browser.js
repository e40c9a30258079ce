#!/usr/bin/env node
'use strict';
// Drives the avatar viewer (web/viewer/index.html in a folder written by `icef view`, served over
// http) in headless Chromium: a screenshot with the UI, screenshots of a dataset camera at neutral
// and with an expression, a render benchmark and CSV playback. Usage:
//   node view_browser.js BASE_URL OUT_DIR [--camera NAME] [--size WxH] [--expr NAME:V] [--bench N]
// Prints one JSON object on stdout; exits 1 if a page logged an error, threw, had a failed request
// (or an HTTP status >= 400), never got ready, or its playback did not advance.

const fs = require('fs');
const path = require('path');
const puppeteer = require(process.env.ICEF_PUPPETEER ||
  '/usr/local/share/icef/puppeteer/node_modules/puppeteer-core');

const CHROMIUM = process.env.ICEF_CHROMIUM || '/usr/bin/chromium';
const CHROMIUM_ARGS = ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
  '--ignore-gpu-blocklist'];
const READY_TIMEOUT_MS = 60000;

const errors = [], warnings = [];
const result = {
  errors, warnings, ready: false, targets: [], camera: null, size: null, expr: null,
  expr_changed: null, fps: null, csv: null, frames_advanced: null,
};

function usage(message) {
  if (message) console.error(`view_browser.js: ${message}`);
  console.error('usage: node view_browser.js BASE_URL OUT_DIR [--camera NAME] [--size WxH] ' +
    '[--expr NAME:V] [--bench N]');
  process.exit(2);
}

function parseArgs(argv) {
  const opts = { camera: null, size: null, expr: null, bench: 120 };
  const positional = [];
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (!a.startsWith('--')) { positional.push(a); continue; }
    const key = a.slice(2);
    if (!(key in opts)) usage(`unknown option ${a}`);
    if (i + 1 >= argv.length) usage(`${a} needs a value`);
    opts[key] = argv[++i];
  }
  if (positional.length !== 2) usage();
  [opts.base, opts.out] = positional;
  opts.base = opts.base.replace(/\/index\.html$/, '').replace(/\/+$/, '');
  if (opts.size !== null && !/^\d+x\d+$/.test(opts.size)) usage(`bad --size ${opts.size}`);
  opts.bench = Number(opts.bench);
  if (!Number.isInteger(opts.bench) || opts.bench < 1) usage('--bench needs a positive integer');
  return opts;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// The viewer's status (window.icefViewer) without its functions, plus the current morph weights.
const snapshot = (page) => page.evaluate(() => {
  const v = window.icefViewer;
  return { targets: v.targets, camera: v.camera, fps: v.fps, csv: v.csv, frame: v.frame,
    weights: v.weights ? v.weights() : null };
});

// Two animation frames: the frame rendered before has reached the screen.
const settle = (page) => page.evaluate(() => new Promise((r) =>
  requestAnimationFrame(() => requestAnimationFrame(() => r()))));

// Opens BASE/index.html + query in a fresh page of width x height CSS pixels (device scale 1),
// collecting its problems under `label`, and waits until the viewer is ready or has failed.
async function open(browser, base, label, query, width, height) {
  const page = await browser.newPage();
  page.on('console', (msg) => {
    const text = `${label}: ${msg.text()}`;
    if (msg.type() === 'error') errors.push(text);
    else if (msg.type() === 'warn' || msg.type() === 'warning') warnings.push(text);
  });
  page.on('pageerror', (e) => errors.push(`${label}: uncaught ${e.message || e}`));
  page.on('requestfailed', (r) => errors.push(`${label}: ${r.url()}: ${r.failure()?.errorText}`));
  page.on('response', (r) => {
    if (r.status() >= 400) errors.push(`${label}: ${r.url()}: HTTP ${r.status()}`);
  });
  await page.setViewport({ width, height, deviceScaleFactor: 1 });
  let ready = false;
  try {
    await page.goto(`${base}/index.html${query}`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.icefViewer && (window.icefViewer.ready || window.icefViewer.error),
      { timeout: READY_TIMEOUT_MS, polling: 100 });
    ready = await page.evaluate(() => window.icefViewer.ready === true);
  } catch (e) {
    errors.push(`${label}: ${e.message}`);
  }
  if (!ready) {
    const why = await page.evaluate(() => window.icefViewer?.error).catch(() => null);
    errors.push(`${label}: viewer not ready${why ? `: ${why}` : ''}`);
  }
  return { page, ready };
}

async function run(opts) {
  fs.mkdirSync(opts.out, { recursive: true });

  // viewer.json tells the default camera, its size and whether there are curves.
  let config = {};
  try {
    const res = await fetch(`${opts.base}/viewer.json`);
    if (!res.ok) throw new Error(`HTTP ${res.status}`);
    config = await res.json();
  } catch (e) {
    errors.push(`viewer.json: ${e.message}`);
  }
  const cameras = config.cameras || [];

  const browser = await puppeteer.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS });
  try {
    // (a) The full page with its panel (also when it failed: it shows the error).
    let { page, ready } = await open(browser, opts.base, 'ui', '', 1024, 640);
    result.ready = ready;
    if (ready) result.targets = (await snapshot(page)).targets;
    await settle(page).catch(() => {});
    await page.screenshot({ path: path.join(opts.out, 'ui.png') });
    await page.close();
    if (!ready) return;

    // (b) A dataset camera, exactly its pixels, neutral; (c) the same with an expression.
    const cam = opts.camera !== null ? cameras.find((c) => c.name === opts.camera) : cameras[0];
    if (opts.camera !== null && !cam) errors.push(`no camera "${opts.camera}" in viewer.json`);
    const size = opts.size || (cam ? `${cam.w}x${cam.h}` : '512x512');
    const [w, h] = size.split('x').map(Number);
    Object.assign(result, { camera: cam ? cam.name : null, size });
    const t = result.targets;
    result.expr = opts.expr || (t.includes('jawOpen') ? 'jawOpen:1' : t.includes('jaw_open') ? 'jaw_open:1'
      : t.length ? `${t[0]}:1` : null);
    const query = `?${cam ? `camera=${encodeURIComponent(cam.name)}&` : ''}size=${size}&ui=0`;
    const shots = {};
    for (const [name, q] of [['neutral', query], ['expr', result.expr && `${query}&expr=${encodeURIComponent(result.expr)}`]]) {
      if (!q) continue;
      ({ page, ready } = await open(browser, opts.base, name, q, w, h));
      if (ready) {
        await settle(page);
        shots[name] = Buffer.from(await page.screenshot({ path: path.join(opts.out, `${name}.png`) }));
      }
      await page.close();
    }
    if (shots.neutral && shots.expr) result.expr_changed = !shots.neutral.equals(shots.expr);

    // (d) Render speed.
    ({ page, ready } = await open(browser, opts.base, 'bench', `?bench=${opts.bench}&size=512x512&ui=0`, 512, 512));
    if (ready) {
      try {
        await page.waitForFunction(() => window.icefViewer.benchDone === true,
          { timeout: READY_TIMEOUT_MS + 2000 * opts.bench, polling: 200 });
        result.fps = (await snapshot(page)).fps;
      } catch (e) {
        errors.push(`bench: not done: ${e.message}`);
      }
    }
    await page.close();

    // (e) CSV playback: the frame and the morph weights change within about 2 s.
    if (config.curves) {
      ({ page, ready } = await open(browser, opts.base, 'play', '?play=1&ui=0', 512, 512));
      if (ready) {
        const first = await snapshot(page);
        result.csv = first.csv;
        result.frames_advanced = false;
        for (const end = Date.now() + 2500; Date.now() < end && !result.frames_advanced;) {
          await sleep(100);
          const now = await snapshot(page);
          result.frames_advanced = now.frame !== first.frame &&
            JSON.stringify(now.weights) !== JSON.stringify(first.weights);
        }
        if (!result.frames_advanced) errors.push('play: the frame or the morph weights did not change in 2.5 s');
      }
      await page.close();
    }
  } finally {
    await browser.close();
  }
}

const opts = parseArgs(process.argv.slice(2));
run(opts).catch((e) => errors.push(`view_browser.js: ${e.stack || e}`)).then(() => {
  console.log(JSON.stringify(result, null, 1));
  process.exitCode = errors.length === 0 && result.ready ? 0 : 1;
});
