// What a connected viewer costs swirl view's simulation, and the page's frame
// time in headless Chromium (docs/performance/view.md).
//
//   make browser-deps   # once: puppeteer-core into tests/browser/node_modules
//   node tools/view_overhead.mjs [--swirl build/swirl] [--chromium /usr/bin/chromium]
//        [--sizes 35000,1000000] [--seconds 20,60] [--rounds 3,2] [--threads 2] [--modes none,socket,chromium]
//        [--surface-cell 1]
//
// For each size, the dam break (examples/dam_break.toml, the column's lattice
// spacing set for about that many particles, dt = 1e-4 s at 10⁶ for its
// smaller h) runs under `swirl view --seconds S` in rounds, each round the
// modes in turn, so a busy machine's drift falls on every mode alike:
//   none      no viewer (the frames are still copied and encoded: swirl does
//             that whether or not anyone watches);
//   socket    a bare WebSocket client (Node's, --experimental-websocket: Node ≥ 20.10,
//             so not Debian 12's Node 18; --modes none,chromium there) that
//             receives the frames and counts their bytes: the server's side alone;
//   surface   the socket client with the fluid's surface turned on (it sends
//             the surface control, view/wire.hpp): swirl makes a mesh of the
//             state copied for a frame whenever its mesher is free, and sends
//             it; compared with socket, the cost of the surface;
//   chromium  the page in headless Chromium on the same machine (WebGL2 on
//             SwiftShader: software drawing, which competes for the cores).
// The solver's speed is swirl's own "steps/s after the set-up" (its summary
// line); the table gives each mode's median and its ratio to none's median,
// the bytes per frame sent, and for chromium the page's median interval
// between drawn frames (ms) and the frames it received per second, and for
// surface the meshes made per second and swirl's mean time to make one
// (mesh and encoding, on the mesher's thread; --surface-cell is passed on).
import { spawn } from "node:child_process";
import { createRequire } from "node:module";
import os from "node:os";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
const arg = (name, fallback) => {
  const i = process.argv.indexOf(`--${name}`);
  return i > 0 ? process.argv[i + 1] : fallback;
};
const swirlPath = path.resolve(arg("swirl", path.join(root, "build/swirl")));
const chromiumPath = arg("chromium", "/usr/bin/chromium");
const sizes = arg("sizes", "35000,1000000").split(",").map(Number);
const seconds = arg("seconds", "20,60").split(",").map(Number);
const rounds = arg("rounds", "3,2").split(",").map(Number);
const threads = arg("threads", "2");
const modes = arg("modes", "none,socket,chromium").split(",");
const surfaceCell = arg("surface-cell", "1");
const { chromiumArgs } = { chromiumArgs: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--window-size=1280,800", "--mute-audio", "--no-first-run"] };  // as tests/browser/view_test.mjs
const requireHarness = createRequire(path.join(root, "tests/browser/package.json"));
const puppeteer = (await import(pathToFileURL(requireHarness.resolve("puppeteer-core")).href)).default;
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const children = new Set();  // ended with this script
for (const sig of ["SIGINT", "SIGTERM", "SIGHUP"])
  process.on(sig, () => { console.error(`view_overhead: ${sig}, stopping`); for (const c of children) c.kill("SIGKILL"); process.exit(1); });
process.on("exit", () => { for (const c of children) c.kill("SIGKILL"); });
const median = (a) => { const s = [...a].sort((x, y) => x - y), m = s.length >> 1; return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2; };

// The dam break's column (0.3 x 0.5 x 0.4 m, cell-centred lattice) at about n particles.
function overrides(n) {
  const count = (s) => Math.floor(0.3 / s + 1e-9) * Math.floor(0.5 / s + 1e-9) * Math.floor(0.4 / s + 1e-9);
  let s = Math.cbrt(0.06 / n);
  while (count(s) < n) s *= 0.999;
  const o = ["--set", `particles.0.spacing=${s.toPrecision(5)}`, "--set", "simulation.end_time=1000"];
  if (n > 200000) o.push("--set", "simulation.dt=1e-4");
  return { o, count: count(s), spacing: s };
}

async function run(n, mode, secs) {
  const { o } = overrides(n);
  let browser = null, page = null;
  if (mode === "chromium")  // started first, so that the page connects right after the set-up
    browser = await puppeteer.launch({ executablePath: chromiumPath, headless: true, args: chromiumArgs,
      defaultViewport: { width: 1280, height: 800 } }), page = await browser.newPage(), children.add(browser.process());
  const swirl = spawn(swirlPath, ["view", path.join(root, "examples/dam_break.toml"), "--open", "never", "--port", "0", "--seconds", String(secs),
    "--threads", threads, "--surface-cell", surfaceCell, ...o], { stdio: ["ignore", "pipe", "pipe"] });
  children.add(swirl);
  let out = "", err = "";
  swirl.stdout.on("data", (d) => { out += d; });
  swirl.stderr.on("data", (d) => { err += d; });
  const done = new Promise((r) => swirl.on("exit", r));
  while (!/live at (\S+)/.test(out) && swirl.exitCode === null) await sleep(20);
  const url = (out.match(/live at (\S+)/) || [])[1];
  let client = null, clientDone = null, page_ = {};
  if (mode === "socket" || mode === "surface") {
    client = spawn(process.execPath, ["--experimental-websocket", "--no-warnings", "-e", `
      const ws = new WebSocket(${JSON.stringify(url.replace("http", "ws") + "ws")}); ws.binaryType = "arraybuffer";
      if (${mode === "surface"}) ws.onopen = () => ws.send(new Uint8Array([10, 1]));  // the surface on
      let frames = 0, bytes = 0; ws.onmessage = (e) => { if (typeof e.data !== "string") { frames++; bytes += e.data.byteLength; } };
      ws.onclose = () => { console.log(JSON.stringify({ frames, bytes })); process.exit(0); };`], { stdio: ["ignore", "ignore", "inherit"] });
    children.add(client);
    clientDone = new Promise((r) => client.on("exit", r));  // now: it may end before swirl's exit is seen
  } else if (mode === "chromium") {
    await page.goto(url);
  }
  if (mode === "chromium") {  // sample the page shortly before the run ends
    const t0 = Date.now();
    await page.waitForFunction(() => window.swirlView && window.swirlView.received >= 2, { timeout: secs * 1000 }).catch(() => {});
    const r0 = await page.evaluate(() => ({ r: window.swirlView.received || 0, t: performance.now() }));
    await sleep(Math.max(0, secs * 1000 - (Date.now() - t0) - 3000));
    page_ = await page.evaluate((r0) => {
      const v = window.swirlView;
      const s = [...v.frameMs].sort((x, y) => x - y);
      return { frameMs: s[s.length >> 1], received_per_s: ((v.received || 0) - r0.r) / ((performance.now() - r0.t) / 1000),
        count: v.count, renderer: (() => { const gl = document.getElementById("view").getContext("webgl2");
          const e = gl.getExtension("WEBGL_debug_renderer_info"); return e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : "?"; })() };
    }, r0);
  }
  await done;
  if (browser) await browser.close();
  if (clientDone) await clientDone;
  const m = out.match(/(\d+) steps in ([\d.]+) s \((\d+) resets; ([\d.]+) steps\/s after ([\d.]+) s of set-up\); (\d+) frames sent \(([\d.]+) MB\)/);
  if (!m) throw new Error(`no summary from swirl view: ${out}\n${err}`);
  const s = out.match(/; (\d+) surface meshes \(([\d.]+) ms a mesh, at most ([\d.]+); (\d+) vertices and (\d+) triangles the last\), (\d+) sent \(([\d.]+) MB\)/);
  const surface = s ? { meshes: Number(s[1]), meshMs: Number(s[2]), meshMaxMs: Number(s[3]), vertices: Number(s[4]),
    triangles: Number(s[5]), meshesSent: Number(s[6]), meshMb: Number(s[7]) } : {};
  return { mode, steps: Number(m[1]), rate: Number(m[4]), setup: Number(m[5]), frames: Number(m[6]), mb: Number(m[7]), ...page_, ...surface };
}

console.log(`# swirl view overhead: ${os.cpus().length} × ${os.cpus()[0].model}, ${new Date().toISOString()}, threads ${threads}`);
for (let k = 0; k < sizes.length; k++) {
  const n = sizes[k], secs = seconds[Math.min(k, seconds.length - 1)], R = rounds[Math.min(k, rounds.length - 1)];
  const { count, spacing } = overrides(n);
  console.log(`\n## ${count} particles (spacing ${spacing.toPrecision(5)} m), ${R} rounds of ${secs} s; frame = 60 + 7·N = ${60 + 7 * count} bytes`);
  const all = Object.fromEntries(modes.map((m) => [m, []]));
  for (let r = 0; r < R; r++)
    for (const mode of modes) {
      const x = await run(n, mode, secs);
      all[mode].push(x);
      console.log(`  round ${r + 1} ${mode.padEnd(8)} ${x.rate.toFixed(3)} steps/s (${x.steps} steps, set-up ${x.setup} s), ` +
        `${x.frames} frames, ${x.frames ? ((x.mb * 1e6) / x.frames / 1e3).toFixed(1) : "-"} kB/frame` +
        (x.frameMs !== undefined ? `, page: ${x.frameMs.toFixed(1)} ms/frame drawn, ${x.received_per_s.toFixed(1)} frames received/s` : "") +
        (x.meshes !== undefined ? `, surface: ${x.meshes} meshes (${(x.meshes / (x.steps / x.rate)).toFixed(1)}/s), ${x.meshMs} ms a mesh ` +
          `(at most ${x.meshMaxMs}), ${x.vertices} vertices and ${x.triangles} triangles the last, ${x.meshesSent} sent, ` +
          `${x.meshesSent ? (x.meshMb * 1e3 / x.meshesSent).toFixed(0) : "-"} kB/mesh` : ""));
    }
  const base = median(all[modes[0]].map((x) => x.rate));
  console.log(`\n| mode | steps/s (median) | ratio to ${modes[0]} | frames sent/s | page frame time (median, ms) | frames received/s | meshes/s | ms a mesh |`);
  console.log("|---|---:|---:|---:|---:|---:|---:|---:|");
  for (const mode of modes) {
    const xs = all[mode], rate = median(xs.map((x) => x.rate));
    const fps = median(xs.map((x) => x.frames / (x.steps / x.rate)));
    const pf = xs[0].frameMs !== undefined ? median(xs.map((x) => x.frameMs)).toFixed(1) : "";
    const pr = xs[0].received_per_s !== undefined ? median(xs.map((x) => x.received_per_s)).toFixed(1) : "";
    const ms = xs[0].meshes !== undefined ? median(xs.map((x) => x.meshes / (x.steps / x.rate))).toFixed(1) : "";
    const mm = xs[0].meshes !== undefined ? median(xs.map((x) => x.meshMs)).toFixed(1) : "";
    console.log(`| ${mode} | ${rate.toFixed(3)} | ${(rate / base).toFixed(3)} | ${fps.toFixed(1)} | ${pf} | ${pr} | ${ms} | ${mm} |`);
  }
  if (all.chromium && all.chromium[0].renderer) console.log(`\nrenderer: ${all.chromium[0].renderer}`);
}
