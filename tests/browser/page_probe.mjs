// Opens one page in headless Chromium through the DevTools protocol, with no dependency
// beyond Node 20 (its built-in WebSocket, enabled by --experimental-websocket), and writes
// what a test needs to judge it as JSON:
//   console: every console message and uncaught exception, with its level;
//   requests: every URL the page asked for (the report must ask for nothing but itself);
//   dialogs: any alert/confirm/prompt the page opened (a script from the data would);
//   result: the value of --eval, an expression evaluated in the page after load (awaited
//           when it is a promise, returned by value: JSON-serialisable).
// Usage: node --experimental-websocket page_probe.mjs --chromium BIN --url URL
//          [--eval EXPR] [--width W --height H] [--timeout-ms N] [--wait-ms N]
//          [--screenshot PNG (after --eval)] [--full-page 0|1 (the whole page; default
//          the window)] --out FILE
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { Buffer } from "node:buffer";
import { tmpdir } from "node:os";
import { join } from "node:path";

function parseArgs(argv) {
  const a = { width: 1280, height: 900, timeoutMs: 120000, waitMs: 500, eval: "null" };
  for (let i = 2; i < argv.length; i += 2) {
    const k = argv[i];
    const v = argv[i + 1];
    if (v === undefined) throw new Error(`page_probe: ${k} needs a value`);
    if (k === "--chromium") a.chromium = v;
    else if (k === "--url") a.url = v;
    else if (k === "--eval") a.eval = v;
    else if (k === "--out") a.out = v;
    else if (k === "--width") a.width = Number(v);
    else if (k === "--height") a.height = Number(v);
    else if (k === "--timeout-ms") a.timeoutMs = Number(v);
    else if (k === "--wait-ms") a.waitMs = Number(v);
    else if (k === "--screenshot") a.screenshot = v;
    else if (k === "--full-page") a.fullPage = v === "1";
    else throw new Error(`page_probe: unknown option ${k}`);
  }
  for (const k of ["chromium", "url", "out"]) if (!a[k]) throw new Error(`page_probe: --${k} is required`);
  return a;
}

const args = parseArgs(process.argv);
const profile = mkdtempSync(join(tmpdir(), "saresgs-chromium-"));
const browser = spawn(
  args.chromium,
  [
    "--headless=new",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--no-sandbox",
    "--disable-gpu-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--disable-extensions",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-quic",
    "--mute-audio",
    `--user-data-dir=${profile}`,
    "--remote-debugging-port=0",
    `--window-size=${args.width},${args.height}`,
    "about:blank",
  ],
  { stdio: ["ignore", "ignore", "pipe"] },
);

let stderr = "";
const out = { console: [], requests: [], dialogs: [], result: null };
let stage = "starting chromium";
const timer = setTimeout(
  () => finish(new Error(`page_probe: timed out after ${args.timeoutMs} ms while ${stage}`), out),
  args.timeoutMs,
);
let finished = false;
function finish(err, value) {
  if (finished) return;
  finished = true;
  clearTimeout(timer);
  try {
    browser.kill("SIGKILL");
  } catch {}
  try {
    rmSync(profile, { recursive: true, force: true });
  } catch {}
  if (err) {
    // what was seen so far still helps: the console often says why a page stalled
    if (value) writeFileSync(args.out, JSON.stringify({ ...value, error: err.message }));
    process.stderr.write(`${err.message}\n${stderr.slice(-2000)}\n`);
    process.exit(1);
  }
  writeFileSync(args.out, JSON.stringify(value));
  process.exit(0);
}

const wsUrl = await new Promise((resolve, reject) => {
  browser.stderr.on("data", (d) => {
    stderr += d.toString();
    const m = stderr.match(/DevTools listening on (ws:\/\/\S+)/);
    if (m) resolve(m[1]);
  });
  browser.on("exit", (code) => reject(new Error(`page_probe: chromium exited (${code}) before listening`)));
}).catch((e) => finish(e));

const ws = new WebSocket(wsUrl);
await new Promise((resolve, reject) => {
  ws.onopen = resolve;
  ws.onerror = () => reject(new Error("page_probe: cannot connect to chromium"));
}).catch((e) => finish(e));

let nextId = 1;
const pending = new Map();
const listeners = [];
ws.onmessage = (ev) => {
  const msg = JSON.parse(ev.data);
  if (msg.id && pending.has(msg.id)) {
    const { resolve, reject } = pending.get(msg.id);
    pending.delete(msg.id);
    if (msg.error) reject(new Error(`${msg.error.message} ${msg.error.data ?? ""}`));
    else resolve(msg.result);
  } else if (msg.method) {
    for (const l of listeners) l(msg);
  }
};
function send(method, params = {}, sessionId) {
  const id = nextId++;
  ws.send(JSON.stringify({ id, method, params, ...(sessionId ? { sessionId } : {}) }));
  return new Promise((resolve, reject) => pending.set(id, { resolve, reject }));
}

try {
  const { targetId } = await send("Target.createTarget", { url: "about:blank" });
  const { sessionId } = await send("Target.attachToTarget", { targetId, flatten: true });
  let loaded = null;
  const loadedP = new Promise((r) => (loaded = r));
  listeners.push((m) => {
    if (m.sessionId !== sessionId) return;
    if (m.method === "Runtime.consoleAPICalled") {
      const text = m.params.args.map((x) => (x.value !== undefined ? String(x.value) : x.description ?? x.type)).join(" ");
      out.console.push({ level: m.params.type, text });
    } else if (m.method === "Runtime.exceptionThrown") {
      const d = m.params.exceptionDetails;
      out.console.push({ level: "exception", text: d.exception?.description ?? d.text });
    } else if (m.method === "Log.entryAdded") {
      out.console.push({ level: m.params.entry.level, text: `[${m.params.entry.source}] ${m.params.entry.text}` });
    } else if (m.method === "Network.requestWillBeSent") {
      out.requests.push(m.params.request.url);
    } else if (m.method === "Page.javascriptDialogOpening") {
      out.dialogs.push({ type: m.params.type, message: m.params.message });
      send("Page.handleJavaScriptDialog", { accept: false }, sessionId).catch(() => {});
    } else if (m.method === "Page.loadEventFired") {
      loaded();
    }
  });
  await send("Page.enable", {}, sessionId);
  await send("Runtime.enable", {}, sessionId);
  await send("Log.enable", {}, sessionId);
  await send("Network.enable", {}, sessionId);
  await send(
    "Emulation.setDeviceMetricsOverride",
    { width: args.width, height: args.height, deviceScaleFactor: 1, mobile: false },
    sessionId,
  );
  stage = "loading the page";
  await send("Page.navigate", { url: args.url }, sessionId);
  await loadedP;
  await new Promise((r) => setTimeout(r, args.waitMs));
  stage = "evaluating --eval";
  const r = await send(
    "Runtime.evaluate",
    { expression: args.eval, awaitPromise: true, returnByValue: true, userGesture: true },
    sessionId,
  );
  if (r.exceptionDetails) {
    out.evalError = r.exceptionDetails.exception?.description ?? r.exceptionDetails.text;
  } else {
    out.result = r.result.value ?? null;
  }
  if (args.screenshot) {
    stage = "taking the screenshot";
    const shot = await send("Page.captureScreenshot", { format: "png", captureBeyondViewport: !!args.fullPage }, sessionId);
    writeFileSync(args.screenshot, Buffer.from(shot.data, "base64"));
  }
  finish(null, out);
} catch (e) {
  finish(e);
}
