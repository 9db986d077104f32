// Loads an mmh report in headless Chromium (SwiftShader WebGL) through the DevTools protocol and
// prints what the browser test checks, as JSON: console errors and uncaught exceptions, network
// requests other than the file itself, the 3D canvas's non-background pixels, the montage node's
// pose after moving the scrubber to each requested frame, the cost of a scrub step and the frame
// rate while playing; the page's tables, plots and counts read back from its DOM; optionally a
// full-page screenshot.
//   node --experimental-websocket browser_check.js --chromium PATH --html FILE
//        [--frames 0,10,...] [--screenshot OUT.png] [--timeout-ms 60000]
//        [--scrub-steps 60] [--play-seconds 1]   (the scrubbing measurement, bench/README.md)
// Exit 0 when the page loaded (the checks are the caller's), 2 on a usage or browser error.
'use strict';
const { spawn } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

function parseArgs(argv) {
  const args = { frames: [], timeoutMs: 60000, scrubSteps: 60, playSeconds: 1 };
  for (let i = 0; i < argv.length; i += 2) {
    const [key, value] = [argv[i], argv[i + 1]];
    if (key === '--chromium') args.chromium = value;
    else if (key === '--html') args.html = path.resolve(value);
    else if (key === '--frames') args.frames = value.split(',').filter((s) => s).map(Number);
    else if (key === '--screenshot') args.screenshot = value;
    else if (key === '--timeout-ms') args.timeoutMs = Number(value);
    else if (key === '--scrub-steps') args.scrubSteps = Number(value);
    else if (key === '--play-seconds') args.playSeconds = Number(value);
    else throw new Error(`unknown argument ${key}`);
  }
  if (!args.chromium || !args.html) throw new Error('--chromium and --html are required');
  return args;
}

function launch(chromium, profile) {
  const child = spawn(chromium, [
    '--headless', '--no-sandbox', '--no-first-run', '--no-default-browser-check',
    '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
    '--remote-debugging-port=0', `--user-data-dir=${profile}`, '--window-size=1100,1400',
    'about:blank'], { stdio: ['ignore', 'ignore', 'pipe'] });
  return new Promise((resolve, reject) => {
    let text = '';
    child.stderr.on('data', (chunk) => {
      text += chunk;
      const match = text.match(/DevTools listening on (ws:\/\/\S+)/);
      if (match) resolve({ child, endpoint: match[1] });
    });
    child.on('exit', (code) => reject(new Error(`chromium exited (${code}): ${text.slice(-2000)}`)));
  });
}

class Cdp {
  constructor(endpoint) {
    this.socket = new WebSocket(endpoint);
    this.next = 1;
    this.pending = new Map();
    this.listeners = [];
    this.socket.onmessage = (event) => {
      const message = JSON.parse(event.data);
      if (message.id && this.pending.has(message.id)) {
        const { resolve, reject } = this.pending.get(message.id);
        this.pending.delete(message.id);
        if (message.error) reject(new Error(JSON.stringify(message.error)));
        else resolve(message.result);
      } else if (message.method) {
        for (const listener of this.listeners) listener(message);
      }
    };
  }
  open() {
    return new Promise((resolve, reject) => {
      this.socket.onopen = resolve;
      this.socket.onerror = () => reject(new Error('DevTools connection failed'));
    });
  }
  send(method, params = {}, sessionId = undefined) {
    const id = this.next++;
    this.socket.send(JSON.stringify({ id, method, params, sessionId }));
    return new Promise((resolve, reject) => this.pending.set(id, { resolve, reject }));
  }
}

async function check(args) {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'mmh-chromium-'));
  const { child, endpoint } = await launch(args.chromium, profile);
  const result = { errors: [], warnings: [], requests: [], ready: false };
  try {
    const cdp = new Cdp(endpoint);
    await cdp.open();
    const { targetId } = await cdp.send('Target.createTarget', { url: 'about:blank' });
    const { sessionId } = await cdp.send('Target.attachToTarget', { targetId, flatten: true });
    const send = (method, params) => cdp.send(method, params, sessionId);
    cdp.listeners.push((m) => {
      if (m.sessionId !== sessionId) return;
      if (m.method === 'Runtime.consoleAPICalled') {
        const text = m.params.args.map((a) => a.value ?? a.description ?? '').join(' ');
        if (m.params.type === 'error' || m.params.type === 'assert') result.errors.push(text);
        if (m.params.type === 'warning') result.warnings.push(text);
      } else if (m.method === 'Runtime.exceptionThrown') {
        const d = m.params.exceptionDetails;
        result.errors.push(d.exception ? d.exception.description : d.text);
      } else if (m.method === 'Log.entryAdded' && m.params.entry.level === 'error') {
        result.errors.push(`${m.params.entry.source}: ${m.params.entry.text}`);
      } else if (m.method === 'Network.requestWillBeSent') {
        const url = m.params.request.url;
        if (!/^(data|blob):/.test(url) && url !== `file://${args.html}`) result.requests.push(url);
      }
    });
    await send('Runtime.enable');
    await send('Log.enable');
    await send('Network.enable');
    await send('Page.enable');
    const evaluate = async (expression) => {
      const r = await send('Runtime.evaluate', { expression, awaitPromise: true, returnByValue: true });
      if (r.exceptionDetails) throw new Error(`${expression}: ${JSON.stringify(r.exceptionDetails)}`);
      return r.result.value;
    };
    const t0 = Date.now();
    await send('Page.navigate', { url: `file://${args.html}` });
    while (Date.now() - t0 < args.timeoutMs) {
      const state = await evaluate(
        "document.body ? (document.body.dataset.ready || (window.mmhReport && window.mmhReport.errors.length ? 'failed' : '')) : ''");
      if (state === 'true') { result.ready = true; break; }
      if (state === 'failed') break;
      await new Promise((r) => setTimeout(r, 100));
    }
    result.load_ms = Date.now() - t0;
    result.page_errors = await evaluate('window.mmhReport ? window.mmhReport.errors : ["no mmhReport"]');
    result.kind = await evaluate('window.mmhReport && window.mmhReport.data.kind');
    result.has_view = await evaluate('!!(window.mmhReport && window.mmhReport.view)');
    // What the page shows, read back from its DOM (tables, plots, cell counts).
    if (result.ready) result.page = await evaluate('mmhReport.inspect()');
    if (result.ready && result.has_view) {
      result.montage_frames = await evaluate('mmhReport.view.times.length');
      result.pixels = await evaluate('mmhReport.view.foregroundPixels()');
      result.poses = [];
      for (const frame of args.frames) {
        // Moves the scrubber as a user's drag does (value, then an input event).
        const pose = await evaluate(`(() => { const s = document.getElementById('scrubber');
          s.value = '${frame}'; s.dispatchEvent(new Event('input'));
          return mmhReport.view.montagePose(); })()`);
        result.poses.push({ frame, ...pose });
      }
      result.scrub = await evaluate(`mmhReport.view.scrubMilliseconds(${args.scrubSteps})`);
      result.scrub_ms = result.scrub.mean;
      // Frame rate while playing: requestAnimationFrame callbacks per second over --play-seconds.
      result.playback_fps = await evaluate(`new Promise((resolve) => {
        mmhReport.view.showFrame(0); mmhReport.view.toggle();
        let n = 0; const t0 = performance.now();
        const f = () => { ++n; if (performance.now() - t0 < ${1000 * args.playSeconds}) requestAnimationFrame(f);
          else { if (mmhReport.view.playing) mmhReport.view.toggle();
                 resolve(n / ((performance.now() - t0) / 1000)); } };
        requestAnimationFrame(f); })`);
      await evaluate('mmhReport.view.showFrame(Math.floor(mmhReport.view.times.length / 3))');
    }
    if (args.screenshot) {
      const metrics = await send('Page.getLayoutMetrics');
      const size = metrics.cssContentSize || metrics.contentSize;
      const shot = await send('Page.captureScreenshot', {
        format: 'png', captureBeyondViewport: true,
        clip: { x: 0, y: 0, width: Math.ceil(size.width), height: Math.min(Math.ceil(size.height), 6000), scale: 1 },
      });
      fs.writeFileSync(args.screenshot, Buffer.from(shot.data, 'base64'));
    }
    await cdp.send('Browser.close').catch(() => {});
    await new Promise((resolve) => {
      if (child.exitCode !== null) return resolve();
      const timer = setTimeout(resolve, 5000);
      child.on('exit', () => { clearTimeout(timer); resolve(); });
    });
  } finally {
    if (child.exitCode === null && child.signalCode === null) child.kill('SIGKILL');
    fs.rmSync(profile, { recursive: true, force: true });
  }
  return result;
}

let args;
try {
  args = parseArgs(process.argv.slice(2));
} catch (error) {
  console.error(String(error));
  process.exit(2);
}
check(args).then((result) => {
  console.log(JSON.stringify(result));
  process.exit(0);
}, (error) => {
  console.error(error.stack || String(error));
  process.exit(2);
});
