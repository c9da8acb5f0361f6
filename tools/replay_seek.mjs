// The time from a seek to its frame for `swirl view RUN_DIR` (docs/performance/view.md):
// a bare WebSocket client (Node >= 20.10: node --experimental-websocket) asks
// for frames in a shuffled order and times each until the frame whose step
// field (a replay's frame index) is the one asked for has arrived whole.
//
//   swirl view RUN_DIR --paused --port 8770 &
//   node --experimental-websocket tools/replay_seek.mjs [--port 8770] [--rounds 5]
const arg = (name, fallback) => { const i = process.argv.indexOf(`--${name}`); return i > 0 ? process.argv[i + 1] : fallback; };
const port = Number(arg("port", 8770)), rounds = Number(arg("rounds", 5));
const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`);
ws.binaryType = "arraybuffer";
let hello = null, waiting = null;
ws.onmessage = (ev) => {
  if (typeof ev.data === "string") { const m = JSON.parse(ev.data); if (m.type === "hello") hello = m; return; }
  const dv = new DataView(ev.data), step = Number(dv.getBigUint64(8, true));
  if (waiting && step === waiting.frame) { waiting.done(performance.now() - waiting.t0, ev.data.byteLength); waiting = null; }
};
await new Promise((ok, fail) => { ws.onopen = ok; ws.onerror = fail; });
while (!hello) await new Promise((r) => setTimeout(r, 10));
const seek = (frame) => new Promise((done) => {
  waiting = { frame, t0: performance.now(), done: (ms, bytes) => done({ ms, bytes }) };
  const b = new DataView(new ArrayBuffer(5)); b.setUint8(0, 8); b.setUint32(1, frame, true); ws.send(b.buffer);
});
const times = []; let bytes = 0;
for (let r = 0; r < rounds; r++) {
  const order = [...Array(hello.frames).keys()].sort(() => Math.random() - 0.5);
  for (const k of order) {
    if (k === 0 && r === 0) continue;  // frame 0 is shown already: a seek to it sends no new read
    const x = await seek(k); times.push(x.ms); bytes = x.bytes;
  }
}
times.sort((a, b) => a - b);
const q = (p) => times[Math.min(times.length - 1, Math.floor(p * times.length))].toFixed(1);
console.log(`${hello.particles} particles, ${hello.frames} frames, ${bytes} bytes a frame: seek to frame received ` +
  `median ${q(0.5)} ms, 90 % ${q(0.9)} ms, max ${q(1)} ms over ${times.length} seeks`);
ws.close();
