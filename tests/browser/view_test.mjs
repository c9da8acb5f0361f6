// swirl view's page in a real browser: Debian's Chromium, headless, driven by
// puppeteer-core (which downloads no browser). CTest runs it (label browser,
// tests/CMakeLists.txt); `make test` installs Chromium and `npm ci`s this folder.
//
//   node view_test.mjs --swirl build/swirl --scene examples/dam_break.toml [--chromium /usr/bin/chromium] [--out DIR]
//
// It starts `swirl view` on the dam break's water as a small pool (3840 particles) and checks, in order:
//   1. the page loads without a script error, WebGL2 is there, frames arrive;
//   2. a screenshot of the canvas (panels hidden) has particles drawn: enough
//      pixels unlike the background, in several shades (lit spheres);
//   3. pause stops the step counter, play moves it again; while paused, the
//      "surface" box (shown: an SPH scene) brings surface meshes that pass the
//      page's checks, and the picture changes from the particles to the water
//      surface; unticked, the particles' picture comes back;
//   4. with "push" ticked, a mouse drag across the fluid moves it: paused, the
//      mouse pressed, dragged along +y (the screen's x axis) and held while the
//      page's step button takes 300 steps, the pool's mean y in the frames
//      received moves along the drag by 2 mm more than over the 300 steps
//      before it without a push (the pool is symmetric across y); a drag back
//      along -y then turns it back by 2 mm or more;
//   5. a second WebSocket opened from the page sends malformed controls and an
//      oversized message: the server closes that socket only, the page's
//      viewer keeps receiving frames of a running simulation, and swirl
//      reports the messages dropped at exit;
//   6. a live parameter: the viscosity slider (2 Pa·s) set to 3 Pa·s and
//      released: the status reads 3 back from the solver, the slider's label
//      shows it, swirl logs the change, and a value over the slider's maximum
//      sent by hand is refused;
// then, on a run folder `swirl run` writes of the dam break's column (0.2 s, 11 frames):
//   7. `swirl view RUN_DIR --paused` serves the page in replay mode: the time
//      slider is shown, the push and the step hidden; a click on the slider shows the
//      frame under the pointer (the frames' positions change with it), the
//      next/previous buttons step one frame, play reaches the last frame, and
//      a screenshot has particles drawn; the surface box brings the last
//      frame's mesh.
// The page's test hook is window.swirlView (web/viewer.js).
import { spawn, spawnSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";

const arg = (name, fallback) => {
  const i = process.argv.indexOf(`--${name}`);
  return i > 0 ? process.argv[i + 1] : fallback;
};
const swirlPath = arg("swirl"), scenePath = arg("scene");
const chromiumPath = arg("chromium", "/usr/bin/chromium");
const outDir = arg("out", "");
if (!swirlPath || !scenePath) {
  console.error("usage: node view_test.mjs --swirl PATH --scene PATH [--chromium PATH] [--out DIR]");
  process.exit(2);
}
// A tree that builds only some targets (the ThreadSanitizer job's) has no swirl
// to run: CTest's SKIP_RETURN_CODE 77 reports the test skipped there.
if (!fs.existsSync(swirlPath)) {
  console.log(`view_test: skipped: ${swirlPath} is not built in this tree`);
  process.exit(77);
}
const puppeteer = await import("puppeteer-core").then((m) => m.default).catch(() => {
  console.error("view_test: puppeteer-core is missing: `npm ci` in tests/browser (make test does it)");
  process.exit(1);
});
// WebGL2 in headless Chromium without a GPU: ANGLE on SwiftShader (software
// Vulkan). Chromium 156 falls back to it by itself today but warns that the
// automatic fallback is going away, so it is asked for explicitly.
// --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start.
const chromiumArgs = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--window-size=800,600", "--mute-audio", "--no-first-run"];

const t0 = Date.now();
const log = (...a) => console.log(`[${((Date.now() - t0) / 1000).toFixed(1)} s]`, ...a);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
let failures = 0;
const check = (ok, what) => { log(ok ? "ok  " : "FAIL", what); if (!ok) failures++; return ok; };

// ---- swirl view ----------------------------------------------------------------
// The dam break's water as a pool 0.2 m deep in a 0.6 m box: 24 x 20 x 8 = 3840
// particles, symmetric across y (no jitter), so only a push moves its mean y
// much; a higher viscosity calms its sloshing (it starts as a lattice).
const pool = ["--set", "box.max=[0.6, 0.5, 0.6]", "--set", "particles.0.max=[0.6, 0.5, 0.2]",
  "--set", "particles.0.spacing=0.025", "--set", "particles.0.jitter=0.0", "--set", "sph.viscosity=2.0"];
const swirl = spawn(swirlPath, ["view", scenePath, "--open", "never", "--port", "0", "--seconds", "120", "--threads", "2",
  ...pool, "--set", "simulation.end_time=1000"], { stdio: ["ignore", "pipe", "pipe"] });
let stdout = "", stderr = "";
swirl.stdout.on("data", (d) => { stdout += d; });
swirl.stderr.on("data", (d) => { stderr += d; });
const exited = new Promise((r) => swirl.on("exit", (code, signal) => r({ code, signal })));
let browser = null, replaying = null;  // the replay's swirl, while it runs
const watchdog = setTimeout(() => { console.error("FAIL: watchdog (170 s)"); swirl.kill("SIGKILL"); replaying?.kill("SIGKILL"); if (browser) browser.process()?.kill("SIGKILL"); process.exit(1); }, 170_000);

async function main() {
  let url = null;
  for (let i = 0; i < 300 && !url; i++) {
    const m = stdout.match(/live at (http:\/\/\S+)/);
    if (m) url = m[1];
    else await sleep(100);
  }
  if (!check(url !== null, `swirl view prints its address (${url})`)) throw new Error(`no URL; stderr: ${stderr}`);

  browser = await puppeteer.launch({ executablePath: chromiumPath, headless: true, args: chromiumArgs,
    defaultViewport: { width: 800, height: 600 } });
  const page = await browser.newPage();
  const pageErrors = [];
  page.on("pageerror", (e) => pageErrors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error" && !m.text().startsWith("Failed to load resource")) pageErrors.push(m.text()); });
  page.on("response", (r) => { if (r.status() >= 400 && !r.url().endsWith("/favicon.ico")) pageErrors.push(`${r.status()} for ${r.url()}`); });
  await page.goto(url, { waitUntil: "load" });
  const view = (f, ...a) => page.evaluate(f, ...a);
  // On a time-out: where the page was (its newest frame and status, any message shown).
  const waitFor = (f, what, timeout = 15_000, ...a) =>
    page.waitForFunction(f, { timeout, polling: 50 }, ...a).catch(async () => {
      const where = await view(() => JSON.stringify({ step: window.swirlView.step, received: window.swirlView.received, frames: window.swirlView.frames, status: window.swirlView.status,
        message: document.getElementById("message").textContent, note: window.swirlView.note })).catch(() => "?");
      throw new Error(`timed out: ${what}; the page: ${where}`);
    });

  // 1. Frames arrive and are drawn.
  const renderer = await view(() => {
    const gl = document.getElementById("view").getContext("webgl2");
    const e = gl && gl.getExtension("WEBGL_debug_renderer_info");
    return gl ? (e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : "WebGL2") : null;
  });
  check(renderer !== null, `WebGL2 context (${renderer})`);
  await waitFor(() => window.swirlView.received >= 5 && window.swirlView.frames >= 10 && window.swirlView.status, "frames");
  const hello = await view(() => window.swirlView.hello);
  check(hello && hello.particles === 3840, `hello: ${hello && hello.particles} particles`);
  // The live plots have the run's diagnostics: energy and the fluid's density error (a fraction of ρ0).
  const plotted = await view(() => window.swirlView.history[window.swirlView.history.length - 1]);
  check(plotted && Number.isFinite(plotted.e) && plotted.err > 0 && plotted.err < 0.5, `plotted diagnostics: ${JSON.stringify(plotted)}`);

  // 2. Screenshot of the canvas with the panels hidden.
  // A screenshot of the canvas alone (panels hidden), decoded in the page:
  // pixels unlike the background, their shades, and (given an earlier one)
  // how many pixels differ from it.
  const shoot = async (name, before = null) => {
    await view(() => { for (const id of ["panel", "bar", "barlo", "barhi", "plot", "message"]) document.getElementById(id).style.visibility = "hidden"; });
    await sleep(200);
    const png = await page.screenshot({ type: "png", clip: { x: 0, y: 0, width: 800, height: 600 } });
    await view(() => { for (const id of ["panel", "bar", "barlo", "barhi", "plot", "message"]) document.getElementById(id).style.visibility = ""; });
    if (outDir) { fs.mkdirSync(outDir, { recursive: true }); fs.writeFileSync(path.join(outDir, name), png); }
    const counts = await view(async (b64, b64before) => {
      const decode = async (b) => { const img = new Image(); img.src = "data:image/png;base64," + b; await img.decode();
        const c = new OffscreenCanvas(img.width, img.height), g = c.getContext("2d"); g.drawImage(img, 0, 0);
        return g.getImageData(0, 0, img.width, img.height).data; };
      const d = await decode(b64), e = b64before ? await decode(b64before) : null;
      const bg = [d[0], d[1], d[2]];  // a corner: the clear colour (0.06, 0.08, 0.1)
      let drawn = 0, changed = 0; const shades = new Set();
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) {
          drawn++; shades.add((d[i] >> 3) << 10 | (d[i + 1] >> 3) << 5 | d[i + 2] >> 3);
        }
        if (e && Math.abs(d[i] - e[i]) + Math.abs(d[i + 1] - e[i + 1]) + Math.abs(d[i + 2] - e[i + 2]) > 24) changed++;
      }
      return { drawn, changed, total: d.length / 4, shades: shades.size, bg };
    }, Buffer.from(png).toString("base64"), before ? Buffer.from(before).toString("base64") : null);
    return { png, ...counts };
  };
  const pixels = await shoot("view.png");
  const frac = pixels.drawn / pixels.total;
  check(pixels.bg.join() === "15,20,26", `background ${pixels.bg} is the clear colour`);
  check(frac > 0.01 && frac < 0.6 && pixels.shades >= 20,
    `screenshot: ${(100 * frac).toFixed(1)} % of pixels drawn, ${pixels.shades} shades`);

  // 3. Pause and resume.
  await page.click("#play");
  await waitFor(() => window.swirlView.paused && window.swirlView.status && window.swirlView.status.paused, "paused");
  const s1 = await view(() => window.swirlView.status.step);
  await sleep(1000);
  const s2 = await view(() => window.swirlView.status.step);
  const f2 = await view(() => window.swirlView.step);
  check(s2 === s1 && f2 <= s2, `paused: the step stays at ${s1} -> ${s2} for 1 s (frame step ${f2})`);

  // The surface, paused (so that only the surface changes the picture): the
  // box ticked brings the mesh of the state shown, drawn instead of the particles.
  // The frame of the paused state first (the colour sent again: a recolour sends it).
  await view(() => sendColour(Number(document.getElementById("colour").value)));
  await waitFor((t) => window.swirlView.step === t, "the paused state's frame", 10_000, s2);
  const particlesShot = await shoot("view-particles.png");
  const box = await view(() => getComputedStyle(document.getElementById("surfacelabel")).display);
  check(box !== "none", `the surface box is shown for an SPH scene (display ${box})`);
  await page.click("#surface");
  await waitFor((t) => window.swirlView.mesh && window.swirlView.mesh.step === t, "the surface of the state shown", 15_000, s2);
  const mesh = await view(() => ({ ...window.swirlView.mesh, rejected: window.swirlView.meshesRejected, why: window.swirlView.meshError }));
  check(mesh.triangles > 1000 && mesh.rejected === 0,
    `a surface mesh of step ${mesh.step}: ${mesh.vertices} vertices, ${mesh.triangles} triangles, ${mesh.rejected} rejected ${mesh.why}`);
  const surfaceShot = await shoot("view-surface.png", particlesShot.png);
  check(surfaceShot.drawn / surfaceShot.total > 0.01 && surfaceShot.changed > 0.02 * particlesShot.drawn,
    `the surface drawn: ${(100 * surfaceShot.drawn / surfaceShot.total).toFixed(1)} % of the pixels, ` +
    `${(100 * surfaceShot.changed / surfaceShot.total).toFixed(1)} % changed from the particles' picture`);
  await page.click("#surface");
  const backShot = await shoot("view-particles-again.png", particlesShot.png);
  check(backShot.changed < 0.001 * backShot.total,
    `unticked: the particles' picture again (${backShot.changed} pixels differ)`);
  await page.click("#play");
  await waitFor((s) => !window.swirlView.paused && window.swirlView.status.step > s + 20, "resumed", 15_000, s2);
  const s3 = await view(() => window.swirlView.status.step);
  check(s3 > s2 + 20, `resumed: the step moves on (${s2} -> ${s3})`);

  // 4. Push, paused and stepped so that the intervals compared span the same
  // steps on a busy machine: the camera looks along -x (yaw 0), so the screen's
  // x axis is world +y; the pointer's point is on the plane through the target.
  await page.click("#play");
  await waitFor(() => window.swirlView.paused && window.swirlView.status.paused, "paused again");
  const mid = await view(() => {  // aim at the pool's middle, 1 m away
    const v = window.swirlView, c = [0, 0, 0];
    for (let i = 0; i < v.positions.length; i++) c[i % 3] += v.positions[i];
    v.target = c.map((s, a) => v.lo[a] + (s / v.count / 65535) * (v.hi[a] - v.lo[a]));
    v.yaw = 0; v.pitch = 0.3; v.distance = 1.0;
    return v.target;
  });
  // 0.12 s of simulated time; a single step also sends its frame and a status,
  // which took up to 150 ms a step with other builds loading the 2 cores, so
  // the 300 steps get a 2-minute bound (about 5 s on an idle machine).
  const kSteps = 300;
  const stepped = async () => {  // kSteps steps with the page's step button; the mean y of the pool before and after
    const meanY = () => view(() => {
      const v = window.swirlView; let s = 0;
      for (let i = 1; i < v.positions.length; i += 3) s += v.positions[i];
      return { y: v.lo[1] + (s / v.count / 65535) * (v.hi[1] - v.lo[1]), step: v.step };
    });
    // One step first: its frame is sent at once (the last frame before a pause may be older).
    const s0 = 1 + await view(() => { document.getElementById("step").click(); return window.swirlView.status.step; });
    await waitFor((t) => window.swirlView.step === t, "a single step's frame", 10_000, s0);
    const a = await meanY();
    await view((n) => { for (let i = 0; i < n; i++) document.getElementById("step").click(); }, kSteps);
    await waitFor((t) => window.swirlView.step === t, `${kSteps} steps (to step ${s0 + kSteps})`, 120_000, s0 + kSteps);
    const b = await meanY();
    return { d: b.y - a.y, steps: `${a.step}-${b.step}` };
  };
  const control = await stepped();
  await page.click("#push");
  const dragWorld = await view(() => [worldAt(300, 300), worldAt(500, 300)]);
  const drag = async (from, to) => {  // press, drag, step while held, release
    await page.mouse.move(from, 300);
    await page.mouse.down();
    for (let i = 1; i <= 5; i++) await page.mouse.move(from + ((to - from) * i) / 5, 300);
    const r = await stepped();
    await page.mouse.up();
    return r;
  };
  const right = await drag(300, 400), left = await drag(400, 300);
  await page.click("#push");
  log(`pushing at (${dragWorld[0].map((v) => v.toFixed(3))}) to (${dragWorld[1].map((v) => v.toFixed(3))}) m, ` +
      `aimed at the pool's centre (${mid.map((v) => v.toFixed(3))})`);
  const mm = (v) => (1000 * v).toFixed(2);
  // The pool sloshes a little (it starts as a lattice), and the first drag's
  // momentum outlasts it: each interval is compared with the one before it.
  check(right.d - control.d > 0.002 && left.d - right.d < -0.002,
    `push: the mean y moves ${mm(control.d)} mm over steps ${control.steps} without a push, ${mm(right.d)} mm ` +
    `(steps ${right.steps}) after a drag along +y, ${mm(left.d)} mm (steps ${left.steps}) after one back along -y`);
  await page.click("#play");
  await waitFor(() => !window.swirlView.paused, "resumed again");

  // 5. Hostile messages on a second socket.
  const hostile = await view(async () => {
    const ws = new WebSocket(`ws://${location.host}/ws`); ws.binaryType = "arraybuffer";
    await new Promise((ok, fail) => { ws.onopen = ok; ws.onerror = fail; });
    const closed = new Promise((ok) => { ws.onclose = (e) => ok(e.code); });
    const nanPush = new DataView(new ArrayBuffer(34)); nanPush.setUint8(0, 7); nanPush.setFloat32(1, NaN, true); nanPush.setUint8(33, 1);
    ws.send(new Uint8Array([99]));             // unknown kind
    ws.send(new Uint8Array([1, 0, 0]));        // pause with a payload: wrong length
    ws.send(new Uint8Array([5, 0, 0]));        // speed, truncated
    ws.send(nanPush.buffer);                   // a NaN push
    ws.send("pause");                          // a text message
    await new Promise((k) => setTimeout(k, 300));
    const openBefore = ws.readyState === WebSocket.OPEN;
    ws.send(new Uint8Array(4096));             // oversized (> 1 KiB)
    const code = await Promise.race([closed, new Promise((k) => setTimeout(() => k("still open"), 5000))]);
    return { openBefore, code };
  });
  check(hostile.openBefore, "the malformed controls are dropped without closing their socket");
  check(hostile.code !== "still open", `the oversized message closes its socket (code ${hostile.code})`);
  const before = await view(() => ({ r: window.swirlView.received, s: window.swirlView.step }));
  await sleep(2000);
  const after = await view(() => ({ r: window.swirlView.received, s: window.swirlView.step, paused: window.swirlView.paused }));
  check(after.r > before.r + 2 && after.s > before.s && !after.paused,
    `the viewer goes on: ${after.r - before.r} frames in 2 s, step ${before.s} -> ${after.s}`);

  // 6. The viscosity slider: set and released (the "change" a release fires).
  const spec = await view(() => {
    const r = document.getElementById("param-viscosity");
    return r ? { min: Number(r.min), max: Number(r.max), value: Number(r.value) } : null;
  });
  check(spec && spec.value === 2 && spec.min === 0 && spec.max === 20,
    `the viscosity slider shows the scene's 2 Pa·s in [0, 20] (${JSON.stringify(spec)})`);
  await view(() => { const r = document.getElementById("param-viscosity"); r.value = 3; r.dispatchEvent(new Event("change")); });
  await waitFor(() => window.swirlView.status.parameters["sph.viscosity"] === 3, "the viscosity's new value in a status");
  const label = await view(() => document.getElementById("param-viscosity").parentElement.textContent);
  check(/viscosity 3 Pa·s/.test(label), `the slider's label shows the new value ("${label.trim()}")`);
  await view(() => { const b = new DataView(new ArrayBuffer(14)); b.setUint8(0, 9); b.setUint8(1, 0); b.setFloat32(2, 50, true);
    const ws = new WebSocket(`ws://${location.host}/ws`); ws.binaryType = "arraybuffer"; ws.onopen = () => ws.send(b.buffer); });
  await waitFor(() => /outside \[0, 20\]/.test(window.swirlView.note), "the refusal of 50 Pa·s", 10_000);
  const v3 = await view(() => window.swirlView.status.parameters["sph.viscosity"]);
  check(v3 === 3, `a viscosity over the slider's range is refused: still ${v3} Pa·s`);
  check(pageErrors.length === 0, `no script errors on the page${pageErrors.length ? ": " + pageErrors.join("; ") : ""}`);
  const frameMs = await view(() => { const a = [...window.swirlView.frameMs].sort((x, y) => x - y); return a[a.length >> 1]; });
  log(`page: median ${frameMs.toFixed(1)} ms between drawn frames (software WebGL2)`);
}

try {
  await main();
} catch (e) {
  check(false, String(e && e.stack || e));
}
if (browser) await browser.close().catch(() => {});
swirl.kill("SIGINT");
const end = await exited;
const summary = stdout.match(/(\d+) steps in .* (\d+) controls, (\d+) dropped, (\d+) viewers/);
log(summary ? summary[0] : `swirl's output: ${stdout} ${stderr}`);
check(end.code === 0, `swirl view ends cleanly (exit ${end.code}, signal ${end.signal})`);
check(summary && Number(summary[3]) >= 5, `swirl counts the malformed messages dropped (${summary && summary[3]})`);
check(/sph\.viscosity 2 Pa·s -> 3 Pa·s/.test(stderr), "swirl logs the viscosity's change with its step");
check(/1 parameter changes, 1 refused/.test(stdout), `swirl counts the change and the refusal (${(stdout.match(/\d+ parameter changes, \d+ refused/) || ["?"])[0]})`);

// ---- 7. swirl view RUN_DIR ------------------------------------------------------------
const runDir = fs.mkdtempSync(path.join(os.tmpdir(), "swirl-replay-"));
async function replay() {
  // The dam break's column (3840 particles), falling for 0.2 s: 11 frames.
  const made = spawnSync(swirlPath, ["run", scenePath, "--out", runDir, "--overwrite", "--threads", "2",
    "--set", "particles.0.spacing=0.025", "--set", "simulation.end_time=0.2"], { encoding: "utf8" });
  if (!check(made.status === 0, `swirl run writes a run folder (exit ${made.status})`)) throw new Error(made.stderr);
  const viewer = replaying = spawn(swirlPath, ["view", runDir, "--open", "never", "--port", "0", "--seconds", "60", "--paused"], { stdio: ["ignore", "pipe", "pipe"] });
  let out = "", err = "";
  viewer.stdout.on("data", (d) => { out += d; });
  viewer.stderr.on("data", (d) => { err += d; });
  const ended = new Promise((r) => viewer.on("exit", (code) => r(code)));
  try {
    let url = null;
    for (let i = 0; i < 100 && !url; i++) { const m = out.match(/at (http:\/\/\S+)/); if (m) url = m[1]; else await sleep(100); }
    if (!check(url !== null && /replaying .* \(11 frames\)/.test(out), `swirl view RUN_DIR prints its address (${out.trim().split("\n")[0]})`))
      throw new Error(`no URL; stderr: ${err}`);
    browser = await puppeteer.launch({ executablePath: chromiumPath, headless: true, args: chromiumArgs,
      defaultViewport: { width: 800, height: 600 } });
    const page = await browser.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(url, { waitUntil: "load" });
    const view = (f, ...a) => page.evaluate(f, ...a);
    const waitFor = (f, what, timeout = 15_000, ...a) =>
      page.waitForFunction(f, { timeout, polling: 50 }, ...a).catch(() => { throw new Error(`timed out: ${what}`); });
    await waitFor(() => window.swirlView.received >= 1 && window.swirlView.status && window.swirlView.frames >= 5, "the first frame");
    const ui = await view(() => ({ mode: window.swirlView.mode, bar: getComputedStyle(document.getElementById("replay")).display,
      push: getComputedStyle(document.getElementById("pushlabel")).display,
      step: getComputedStyle(document.getElementById("step")).display, max: document.getElementById("slider").max,
      frame: window.swirlView.step }));
    check(ui.mode === "replay" && ui.bar !== "none" && ui.push === "none" && ui.step === "none" && ui.max === "10" && ui.frame === 0,
      `replay mode: the slider over 11 frames shown, the push and step hidden, frame 0 first (${JSON.stringify(ui)})`);
    const meanZ = () => view(() => { const v = window.swirlView; let s = 0;
      for (let i = 2; i < v.positions.length; i += 3) s += v.positions[i];
      return { z: v.lo[2] + (s / v.count / 65535) * (v.hi[2] - v.lo[2]), step: v.step }; });
    const z0 = await meanZ();
    // A click on the slider, 70 % along: the frame under the pointer.
    const box = await (await page.$("#slider")).boundingBox();
    await page.mouse.click(box.x + 0.7 * box.width, box.y + box.height / 2);
    const asked = Number(await view(() => document.getElementById("slider").value));
    await waitFor((k) => window.swirlView.step === k && window.swirlView.status.frame === k, `frame ${asked}`, 10_000, asked);
    const zk = await meanZ();
    check(asked >= 5 && asked <= 9 && z0.z - zk.z > 0.005,
      `the slider at frame ${asked}: that frame is shown, the column has fallen (mean z ${(1000 * z0.z).toFixed(1)} -> ${(1000 * zk.z).toFixed(1)} mm)`);
    await page.click("#next");
    await waitFor((k) => window.swirlView.step === k + 1, "the next frame", 10_000, asked);
    const next = await view(() => window.swirlView.step);
    await page.click("#prev"); await page.click("#prev");
    await waitFor((k) => window.swirlView.step === k - 1, "two frames back", 10_000, asked);
    const back = await view(() => ({ step: window.swirlView.step, slider: Number(document.getElementById("slider").value) }));
    check(next === asked + 1 && back.step === asked - 1 && back.slider === asked - 1,
      `next and previous step one frame (${asked} -> ${next} -> ${back.step}, the slider at ${back.slider})`);
    await page.click("#play");
    await waitFor(() => window.swirlView.step === 10 && window.swirlView.status.at_end, "the last frame", 15_000);
    const end = await view(() => ({ slider: document.getElementById("slider").value, paused: window.swirlView.paused }));
    check(end.slider === "10" && end.paused, `play reaches the last frame and stops there (${JSON.stringify(end)})`);
    await page.click("#surface");  // the last frame's surface
    await waitFor(() => window.swirlView.mesh && window.swirlView.mesh.step === 10, "the last frame's surface", 15_000);
    const rm = await view(() => ({ ...window.swirlView.mesh, rejected: window.swirlView.meshesRejected }));
    check(rm.triangles > 1000 && rm.rejected === 0, `replay: the surface of frame ${rm.step}, ${rm.triangles} triangles`);
    const png = await page.screenshot({ type: "png", clip: { x: 0, y: 0, width: 800, height: 600 } });
    if (outDir) fs.writeFileSync(path.join(outDir, "replay.png"), png);
    const drawn = await view(async (b64) => {
      const img = new Image(); img.src = "data:image/png;base64," + b64; await img.decode();
      const c = new OffscreenCanvas(img.width, img.height), g = c.getContext("2d"); g.drawImage(img, 0, 0);
      const d = g.getImageData(0, 0, img.width, img.height).data; let n = 0;
      for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - 15) + Math.abs(d[i + 1] - 20) + Math.abs(d[i + 2] - 26) > 24) n++;
      return n / (d.length / 4);
    }, Buffer.from(png).toString("base64"));
    check(drawn > 0.01, `replay screenshot (the surface): ${(100 * drawn).toFixed(1)} % of pixels drawn`);
    check(errors.length === 0, `no script errors on the replay page${errors.length ? ": " + errors.join("; ") : ""}`);
  } finally {
    if (browser) await browser.close().catch(() => {});
    browser = null;
    viewer.kill("SIGINT");
    const code = await ended;
    check(code === 0, `swirl view RUN_DIR ends cleanly (exit ${code}): ${(out.match(/\d+ frames shown.*/) || [""])[0]}`);
  }
}
try {
  await replay();
} catch (e) {
  check(false, String(e && e.stack || e));
}
fs.rmSync(runDir, { recursive: true, force: true });
clearTimeout(watchdog);
log(failures ? `${failures} check(s) failed` : "all checks passed");
process.exit(failures ? 1 : 0);
