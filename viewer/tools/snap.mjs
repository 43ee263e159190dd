// Opens a viewer page (written by acyclic-view) in headless Chromium, waits
// until the page says it has loaded and drawn, prints the page's own state
// (window.acyclicViewer) as JSON on stdout, and saves a screenshot.
//
//   node viewer/tools/snap.mjs PAGE_DIR [--query 'stance=3&hud=0'] [--png OUT.png]
//        [--width 1200] [--height 800] [--visit-stances] [--state OUT.json]
//
// --visit-stances: calls setStance(i) for every stance and setFrame(i) for
// every frame and reports what each drew (for tests). --state: the JSON goes
// to that file instead of stdout.
// Exit: 0 loaded, 1 the page reported an error or did not load, 2 bad usage
// or no browser (CHROMIUM names it; default /usr/bin/chromium).
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import puppeteer from 'puppeteer-core';

function usage(msg) {
  console.error('snap: ' + msg);
  process.exit(2);
}
const args = process.argv.slice(2);
const opt = { query: '', png: null, width: 1200, height: 800, visit: false, state: null };
let dir = null;
for (let i = 0; i < args.length; ++i) {
  const a = args[i];
  const next = () => (i + 1 < args.length ? args[++i] : usage(a + ' needs a value'));
  if (a === '--query') opt.query = next();
  else if (a === '--png') opt.png = next();
  else if (a === '--width') opt.width = Number(next());
  else if (a === '--height') opt.height = Number(next());
  else if (a === '--visit-stances') opt.visit = true;
  else if (a === '--state') opt.state = next();
  else if (a === '--help' || a === '-h') {
    console.log(fs.readFileSync(new URL(import.meta.url), 'utf8').split('\n').filter((l) => l.startsWith('//')).join('\n'));
    process.exit(0);
  } else if (!a.startsWith('--') && dir === null) dir = a;
  else usage('unknown argument ' + a);
}
if (!dir) usage('PAGE_DIR missing (a folder written by acyclic-view)');
const index = path.resolve(dir, 'index.html');
if (!fs.existsSync(index)) usage(index + ' not found (write it with acyclic-view)');
const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
if (!fs.existsSync(chromium))
  usage(chromium + ' not found: headless Chromium is needed (scripts/install-deps installs Debian\'s chromium)');

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  // No GPU here: WebGL through SwiftShader (software), the same pixels on every machine.
  // --disable-dev-shm-usage: containers often have a tiny /dev/shm.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-gpu-sandbox', '--disable-dev-shm-usage',
    '--hide-scrollbars', '--mute-audio', '--font-render-hinting=none'],
  defaultViewport: { width: opt.width, height: opt.height, deviceScaleFactor: 1 },
});
let code = 0;
try {
  const page = await browser.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(m.type() + ': ' + m.text()));
  page.on('pageerror', (e) => logs.push('pageerror: ' + e.message));
  // Offline by construction: any request that is not a local file fails the run.
  await page.setRequestInterception(true);
  const remote = [];
  page.on('request', (r) => {
    if (r.url().startsWith('file:') || r.url().startsWith('data:')) r.continue();
    else { remote.push(r.url()); r.abort(); }
  });
  const url = pathToFileURL(index).href + (opt.query ? '?' + opt.query : '');
  await page.goto(url, { waitUntil: 'load', timeout: 60000 });
  await page.waitForFunction('window.acyclicViewer && (window.acyclicViewer.error || (window.acyclicViewer.loaded && window.acyclicViewer.renders > 0))',
    { timeout: 60000 });
  let visits = null;
  if (opt.visit) {
    visits = await page.evaluate(async () => {
      const v = window.acyclicViewer;
      if (v.error) return null;
      const stances = [], frames = [];
      for (let i = 0; i < v.stances; ++i) { const c = v.setStance(i); stances.push({ current: c, drawn: v.drawn }); }
      for (let i = 0; i < v.frames; ++i) { const c = v.setFrame(i); frames.push({ current: c, drawn: v.drawn }); }
      // Play from the start: the timeline moves within 30 s of wall time (the
      // renders queued by the visits above go first on a software renderer,
      // and a loaded machine gives animation frames late).
      let play = null;
      if (v.frames > 1) {
        v.setFrame(0);
        v.play();
        const playing = v.playing;
        for (let k = 0; k < 300 && !(v.current.t > 0); ++k) await new Promise((r) => setTimeout(r, 100));
        play = { playing, t: v.current.t, mode: v.current.mode };
        v.pause();
      }
      return { stances, frames, play };
    });
    // Back to what the query asked for, for the screenshot.
    await page.goto(url, { waitUntil: 'load' });
    await page.waitForFunction('window.acyclicViewer && (window.acyclicViewer.error || (window.acyclicViewer.loaded && window.acyclicViewer.renders > 0))');
  }
  const st = await page.evaluate(() => {
    const v = window.acyclicViewer;
    const out = {};
    for (const [k, val] of Object.entries(v)) if (typeof val !== 'function') out[k] = val;
    return out;
  });
  if (opt.png) await page.screenshot({ path: opt.png });
  const report = JSON.stringify({ url, state: st, visits, remote_requests: remote, console: logs }, null, 1);
  if (opt.state) fs.writeFileSync(opt.state, report + '\n');
  else console.log(report);
  if (st.error || !st.loaded || remote.length) code = 1;
  if (st.error) console.error('snap: the page reports: ' + st.error);
  if (remote.length) console.error('snap: the page asked the network for ' + remote.join(', '));
} catch (e) {
  console.error('snap: ' + e.message);
  code = 1;
} finally {
  await browser.close();
}
process.exit(code);
