// A screenshot of swirl view's page on a running scene, for the README:
// starts `swirl view SCENE`, opens the page in Debian's Chromium (headless,
// puppeteer-core from tests/browser/node_modules: `make browser-deps`), waits
// until the newest frame's simulated time reaches --time, and saves the page.
//
//   node tools/view_screenshot.mjs --swirl build/swirl --scene examples/dam_break.toml \
//        --time 0.4 --out docs/images/view_dam_break.png [--set key=value]... [--yaw 0.6 --pitch 0.35 --zoom 1.5]
//        [--open-after SECONDS]
import { spawn } from "node:child_process";
import fs from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";

const argv = process.argv.slice(2);
const arg = (name, fallback) => { const i = argv.indexOf(`--${name}`); return i >= 0 ? argv[i + 1] : fallback; };
const sets = argv.flatMap((a, i) => (a === "--set" ? ["--set", argv[i + 1]] : []));
const swirlPath = arg("swirl"), scenePath = arg("scene"), outPath = arg("out");
const until = Number(arg("time", "0")), chromium = arg("chromium", "/usr/bin/chromium");
if (!swirlPath || !scenePath || !outPath) {
  console.error("usage: node tools/view_screenshot.mjs --swirl PATH --scene PATH --out FILE.png [--time T] [--set k=v]...");
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, "..", "tests", "browser", "package.json"));
const puppeteer = require("puppeteer-core");

const swirl = spawn(swirlPath, ["view", scenePath, "--open", "never", "--port", "0", "--threads", "2", ...sets],
  { stdio: ["ignore", "pipe", "inherit"] });
let stdout = "";
swirl.stdout.on("data", (d) => { stdout += d; });
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
let browser = null;
try {
  let url = null;
  for (let i = 0; i < 600 && !url; i++) { url = stdout.match(/live at (http:\/\/\S+)/)?.[1] ?? null; if (!url) await sleep(100); }
  if (!url) throw new Error("swirl view printed no address");
  // --open-after S: let the run go S seconds before the page opens (Chromium's
  // software rendering would otherwise take the cores the run needs).
  await sleep(1000 * Number(arg("open-after", "0")));
  browser = await puppeteer.launch({ executablePath: chromium, headless: true, protocolTimeout: 40 * 60_000,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1000,640"],
    defaultViewport: { width: 1000, height: 640 } });
  const page = await browser.newPage();
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction((t) => window.swirlView.received > 2 && window.swirlView.time >= t,
    { timeout: 30 * 60_000, polling: 200 }, until);
  await page.click("#play");  // pause, so the picture is of one frame
  await page.waitForFunction(() => window.swirlView.paused, { timeout: 10_000 });
  // The camera, as the page keeps it (window.swirlView: yaw, pitch, distance as a factor of the framed one).
  const camera = { yaw: arg("yaw"), pitch: arg("pitch"), zoom: arg("zoom") };
  await page.evaluate((c) => {
    const v = window.swirlView;
    if (c.yaw) v.yaw = Number(c.yaw);
    if (c.pitch) v.pitch = Number(c.pitch);
    if (c.zoom) v.distance /= Number(c.zoom);
  }, camera);
  await sleep(1500);
  fs.mkdirSync(path.dirname(outPath), { recursive: true });
  await page.screenshot({ path: outPath, type: "png" });
  const t = await page.evaluate(() => window.swirlView.time);
  console.log(`view_screenshot: ${outPath} at t = ${t}`);
} finally {
  if (browser) await browser.close();
  swirl.kill("SIGTERM");
}
