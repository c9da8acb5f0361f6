// swirl view's page: decodes the server's frames and surface meshes
// (include/swirl/view/wire.hpp has the layouts), draws the particles as lit
// spheres (WebGL2 point-sprite impostors) or the fluid as its surface (an
// opaque water material) and sends the controls back. Written for swirl; no
// libraries.
"use strict";

const token = new URLSearchParams(location.search).get("token");
const canvas = document.getElementById("view");
const gl = canvas.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true });
const ui = (id) => document.getElementById(id);

// ---- State -------------------------------------------------------------------
const state = {
  hello: null, frame: null, count: 0, lo: [0, 0, 0], hi: [1, 1, 1],
  yaw: 0.6, pitch: 0.35, distance: 3, target: [0, 0, 0], framed: false,
  paused: false, status: null, history: [], frames: 0, lastDraw: performance.now(), fps: 0,
  positions: null, frameMs: [], mode: "live", parameters: {}, note: "",
  surface: false, mesh: null, meshes: 0, meshesRejected: 0, meshError: "",
};
// The test hook (tests/browser/view_test.mjs, tools/view_overhead.mjs) and the
// console: window.swirlView is this state: hello (the server's hello), step and
// time (newest frame's), lo/hi (its quantisation box), count and positions
// (its u16 x,y,z triples: lo + q/65535·(hi − lo)), received (frames decoded),
// status (newest status message: step, paused, steps_per_second...), paused,
// frames (drawn) and frameMs (the last 240 intervals between drawn frames, ms);
// mode ("live" or "replay": then step is the frame's index in the run and
// status.frame / status.frames say where the replay is), parameters (the live
// parameters' current values by scene key, from the newest status) and note
// (the last parameter change or refusal the server reported); surface (the
// "surface" box: the fluid drawn as its mesh), mesh (the newest mesh drawn:
// step, time, vertices, triangles), meshes (mesh messages accepted) and
// meshesRejected / meshError (those refused by the checks in onMesh, and why).
// The camera (yaw, pitch, distance, target) may be set; worldAt(x, y) is global.
window.swirlView = state;

// ---- Maths -------------------------------------------------------------------
function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}
function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
function normalise(a) { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }
function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function eye() {
  const c = Math.cos(state.pitch), t = state.target, d = state.distance;
  return [t[0] + d * c * Math.cos(state.yaw), t[1] + d * c * Math.sin(state.yaw), t[2] + d * Math.sin(state.pitch)];
}
function basis() {  // camera axes: right, up, forward (z is up in swirl's scenes)
  const f = normalise(sub(state.target, eye()));
  const r = normalise(cross(f, [0, 0, 1]));
  return { r, u: cross(r, f), f };
}
function lookAt() {
  const e = eye(), { r, u, f } = basis();
  return [r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0, -dot(r, e), -dot(u, e), dot(f, e), 1];
}

// ---- Drawing -----------------------------------------------------------------
const vs = `#version 300 es
in vec3 q; in float c;
uniform mat4 view, proj; uniform vec3 lo, span; uniform float radius, height;
out float colour;
void main() {
  vec3 p = lo + q / 65535.0 * span;
  vec4 v = view * vec4(p, 1.0);
  gl_Position = proj * v;
  gl_PointSize = max(1.5, height * proj[1][1] * radius / -v.z);
  colour = c / 255.0;
}`;
const fs = `#version 300 es
precision mediump float;
in float colour; uniform int additive; out vec4 outColor;
vec3 ramp(float t) {  // dark blue - cyan - yellow - red
  return clamp(vec3(1.5 * t - 0.2, 1.6 * t * (1.3 - t) + 0.15, 1.0 - 1.4 * t + 0.3), 0.0, 1.0);
}
void main() {
  vec2 d = gl_PointCoord * 2.0 - 1.0; float r2 = dot(d, d);
  if (r2 > 1.0) discard;
  vec3 n = vec3(d.x, -d.y, sqrt(1.0 - r2));
  float light = 0.35 + 0.65 * max(dot(n, normalize(vec3(0.4, 0.5, 0.8))), 0.0);
  if (additive == 1) outColor = vec4(ramp(colour) * 0.18 * (1.0 - r2), 1.0);
  else outColor = vec4(ramp(colour) * light, 1.0);
}`;
function compile(type, src) {
  const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
const program = gl.createProgram();
gl.attachShader(program, compile(gl.VERTEX_SHADER, vs));
gl.attachShader(program, compile(gl.FRAGMENT_SHADER, fs));
gl.bindAttribLocation(program, 0, "q"); gl.bindAttribLocation(program, 1, "c");
gl.linkProgram(program);
const uni = {};
for (const n of ["view", "proj", "lo", "span", "radius", "height", "additive"]) uni[n] = gl.getUniformLocation(program, n);
const vao = gl.createVertexArray(), qbuf = gl.createBuffer(), cbuf = gl.createBuffer();
gl.bindVertexArray(vao);
gl.bindBuffer(gl.ARRAY_BUFFER, qbuf); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 3, gl.UNSIGNED_SHORT, false, 0, 0);
gl.bindBuffer(gl.ARRAY_BUFFER, cbuf); gl.enableVertexAttribArray(1); gl.vertexAttribPointer(1, 1, gl.UNSIGNED_BYTE, false, 0, 0);

function draw() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  gl.viewport(0, 0, w, h);
  gl.clearColor(0.06, 0.08, 0.1, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  // The surface instead of the particles once a mesh has come (until then, the particles).
  if (state.surface && state.mesh) drawMesh(w, h);
  else if (state.count > 0) {
    const gravity = state.hello && state.hello.gravity && !state.hello.sph;
    gl.useProgram(program);
    gl.uniformMatrix4fv(uni.view, false, lookAt());
    gl.uniformMatrix4fv(uni.proj, false, perspective(0.8, w / h, state.distance * 0.01, state.distance * 100));
    gl.uniform3fv(uni.lo, state.lo);
    gl.uniform3fv(uni.span, sub(state.hi, state.lo));
    gl.uniform1f(uni.radius, particleRadius());
    gl.uniform1f(uni.height, h / 2);
    gl.uniform1i(uni.additive, gravity ? 1 : 0);
    if (gravity) { gl.disable(gl.DEPTH_TEST); gl.enable(gl.BLEND); gl.blendFunc(gl.ONE, gl.ONE); }
    else { gl.enable(gl.DEPTH_TEST); gl.disable(gl.BLEND); }
    gl.bindVertexArray(vao);
    gl.drawArrays(gl.POINTS, 0, state.count);
    gl.bindVertexArray(null);
  }
  const now = performance.now();
  state.fps = 0.9 * state.fps + 0.1 * (1000 / Math.max(1, now - state.lastDraw));
  state.frameMs.push(now - state.lastDraw);
  if (state.frameMs.length > 240) state.frameMs.shift();
  state.lastDraw = now;
  state.frames++;
  requestAnimationFrame(draw);
}
function particleRadius() {  // half the mean spacing of the particles in their bounds
  const s = sub(state.hi, state.lo), vol = Math.max(s[0] * s[1] * s[2], 1e-30);
  return 0.5 * Math.cbrt(vol / Math.max(state.count, 1));
}

// ---- The water surface --------------------------------------------------------
// An opaque water material, as swirl render --surface draws it (render/water.hpp):
// a deep-blue Lambert body (35 % ambient), Schlick's Fresnel (F0 = 0.02) towards
// a pale sky at grazing angles, a Blinn-Phong highlight, the light fixed to the
// camera. Opaque so that the depth test alone orders the triangles (a
// transparent surface would need them sorted every frame).
const waterVs = `#version 300 es
in vec3 q; in vec3 n;
uniform mat4 view, proj; uniform vec3 lo, span;
out vec3 normal; out vec3 where;
void main() {
  vec4 v = view * vec4(lo + q / 65535.0 * span, 1.0);
  where = v.xyz; normal = mat3(view) * n;
  gl_Position = proj * v;
}`;
const waterFs = `#version 300 es
precision mediump float;
in vec3 normal; in vec3 where; out vec4 outColor;
void main() {
  vec3 N = normalize(normal), V = normalize(-where), L = normalize(vec3(-0.35, 0.75, 0.55));
  if (!gl_FrontFacing) N = -N;  // seen from inside the fluid
  float body = 0.35 + 0.65 * max(dot(N, L), 0.0);
  float fresnel = 0.02 + 0.98 * pow(1.0 - max(dot(N, V), 0.0), 5.0);
  float highlight = 0.7 * pow(max(dot(N, normalize(L + V)), 0.0), 80.0);
  vec3 c = (1.0 - fresnel) * vec3(0.02, 0.20, 0.40) * body + fresnel * vec3(0.72, 0.86, 0.96) + highlight;
  outColor = vec4(min(c, vec3(1.0)), 1.0);
}`;
const water = gl.createProgram();
gl.attachShader(water, compile(gl.VERTEX_SHADER, waterVs));
gl.attachShader(water, compile(gl.FRAGMENT_SHADER, waterFs));
gl.bindAttribLocation(water, 0, "q"); gl.bindAttribLocation(water, 1, "n");
gl.linkProgram(water);
const wuni = {};
for (const n of ["view", "proj", "lo", "span"]) wuni[n] = gl.getUniformLocation(water, n);
const meshVao = gl.createVertexArray(), mqbuf = gl.createBuffer(), mnbuf = gl.createBuffer(), mibuf = gl.createBuffer();
gl.bindVertexArray(meshVao);
gl.bindBuffer(gl.ARRAY_BUFFER, mqbuf); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 3, gl.UNSIGNED_SHORT, false, 0, 0);
gl.bindBuffer(gl.ARRAY_BUFFER, mnbuf); gl.enableVertexAttribArray(1); gl.vertexAttribPointer(1, 3, gl.BYTE, true, 0, 0);
gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mibuf);  // part of the VAO's state
gl.bindVertexArray(null);
const meshGl = { count: 0, type: 0, lo: [0, 0, 0], span: [0, 0, 0] };

// A mesh message ("SWVM"): every field checked before anything is drawn; a
// message that fails a check is counted and dropped, the last good mesh stays.
function onMesh(buffer) {
  const dv = new DataView(buffer), reject = (why) => { state.meshesRejected++; state.meshError = why; };
  if (buffer.byteLength < 64) return reject(`${buffer.byteLength} bytes, shorter than the header`);
  if (dv.getUint16(4, true) !== 1) return reject(`version ${dv.getUint16(4, true)}`);
  const b = dv.getUint16(6, true), v = dv.getUint32(24, true), t = dv.getUint32(28, true);
  if (b !== 2 && b !== 4) return reject(`${b}-byte indices`);
  if (b === 2 && v > 65536) return reject(`2-byte indices for ${v} vertices`);
  if (buffer.byteLength !== 64 + 3 * b * t + 9 * v) return reject(`${buffer.byteLength} bytes for ${v} vertices, ${t} triangles`);
  const lo = [0, 1, 2].map((a) => dv.getFloat32(32 + 4 * a, true)), hi = [0, 1, 2].map((a) => dv.getFloat32(44 + 4 * a, true));
  if (![...lo, ...hi].every(Number.isFinite) || lo.some((x, a) => x > hi[a])) return reject("bounds not finite, or lo > hi");
  const indices = b === 2 ? new Uint16Array(buffer, 64, 3 * t) : new Uint32Array(buffer, 64, 3 * t);
  for (let k = 0; k < indices.length; k++) if (indices[k] >= v) return reject(`index ${indices[k]} of ${v} vertices`);
  gl.bindVertexArray(null);
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, mibuf); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, mqbuf); gl.bufferData(gl.ARRAY_BUFFER, new Uint16Array(buffer, 64 + 3 * b * t, 3 * v), gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, mnbuf); gl.bufferData(gl.ARRAY_BUFFER, new Int8Array(buffer, 64 + 3 * b * t + 6 * v, 3 * v), gl.DYNAMIC_DRAW);
  Object.assign(meshGl, { count: 3 * t, type: b === 2 ? gl.UNSIGNED_SHORT : gl.UNSIGNED_INT, lo, span: sub(hi, lo) });
  state.mesh = { step: Number(dv.getBigUint64(8, true)), time: dv.getFloat64(16, true), vertices: v, triangles: t };
  state.meshes++;
}
function drawMesh(w, h) {
  gl.useProgram(water);
  gl.uniformMatrix4fv(wuni.view, false, lookAt());
  gl.uniformMatrix4fv(wuni.proj, false, perspective(0.8, w / h, state.distance * 0.01, state.distance * 100));
  gl.uniform3fv(wuni.lo, meshGl.lo);
  gl.uniform3fv(wuni.span, meshGl.span);
  gl.enable(gl.DEPTH_TEST); gl.disable(gl.BLEND);
  gl.bindVertexArray(meshVao);
  gl.drawElements(gl.TRIANGLES, meshGl.count, meshGl.type, 0);
  gl.bindVertexArray(null);
}

// ---- Frames and messages -------------------------------------------------------
function onFrame(buffer) {
  const dv = new DataView(buffer);
  if (buffer.byteLength < 60 || dv.getUint32(0, true) !== 0x46565753) return;
  const n = dv.getUint32(24, true);
  if (buffer.byteLength !== 60 + 7 * n) return;
  state.count = n;
  state.step = Number(dv.getBigUint64(8, true));
  state.time = dv.getFloat64(16, true);
  for (let a = 0; a < 3; a++) { state.lo[a] = dv.getFloat32(28 + 4 * a, true); state.hi[a] = dv.getFloat32(40 + 4 * a, true); }
  state.colourRange = [dv.getFloat32(52, true), dv.getFloat32(56, true)];
  gl.bindBuffer(gl.ARRAY_BUFFER, qbuf); gl.bufferData(gl.ARRAY_BUFFER, state.positions = new Uint16Array(buffer, 60, 3 * n), gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, cbuf); gl.bufferData(gl.ARRAY_BUFFER, new Uint8Array(buffer, 60 + 6 * n, n), gl.DYNAMIC_DRAW);
  if (!state.framed) frameCamera();
  state.received = (state.received || 0) + 1;
  ui("barlo").textContent = state.colourRange[0].toPrecision(3);
  ui("barhi").textContent = state.colourRange[1].toPrecision(3);
}
function frameCamera() {
  const b = state.hello && state.hello.box;
  const lo = b ? b.slice(0, 3) : state.lo, hi = b ? b.slice(3) : state.hi;
  state.target = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
  state.distance = 1.8 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  state.framed = true;
}
function onText(text) {
  const m = JSON.parse(text);
  if (m.type === "hello") {
    state.hello = m;
    ui("scene").textContent = m.scene + " · " + m.particles + " particles";
    const sel = ui("colour"); sel.innerHTML = "";
    m.fields.forEach((f, i) => { const o = document.createElement("option"); o.value = i; o.textContent = f; sel.appendChild(o); });
    sel.value = m.colour;
    setPaused(m.paused);
    state.mode = m.mode || "live";
    // The surface box: only where the server can make a surface (a fluid), ticked when it starts on (--surface).
    ui("surfacelabel").style.display = m.surface ? "" : "none";
    if (!m.surface) setSurface(false, false);
    else if (m.surface_on) setSurface(true, false);
    if (state.mode === "replay") setUpReplay(m); else setUpParameters(m.parameters || []);
  } else if (m.type === "status") {
    state.status = m;
    setPaused(m.paused || m.at_end);
    if (m.mode === "replay") {
      ui("stats").textContent = `frame ${m.frame} of ${m.frames - 1} · t = ${Number(m.time).toPrecision(4)} · ` +
        `${m.particles} particles · ${state.fps.toFixed(0)} fps` + (m.at_end ? " · last frame" : "") + surfaceText(m);
      ui("frameinfo").textContent = `frame ${m.frame} / ${m.frames - 1} · t = ${Number(m.time).toPrecision(4)}`;
      // The slider follows the frame shown, but not while dragged or while a seek is on its way.
      if (seek && (m.frame === seek.frame || performance.now() - seek.at > 2000)) seek = null;
      if (!scrubbing && !seek) ui("slider").value = m.frame;
      return;
    }
    state.history.push({ e: m.kinetic_energy + m.potential_energy, rate: m.steps_per_second, err: densityError(m) });
    if (state.history.length > 240) state.history.shift();
    ui("stats").textContent = `step ${m.step} · t = ${Number(m.time).toPrecision(4)} · ${m.steps_per_second.toFixed(1)} steps/s · ` +
      `${state.fps.toFixed(0)} fps` + (m.at_end ? " · end of run" : "") + surfaceText(m);
    if (m.parameters) showParameters(m.parameters);
    plot();
  } else if (m.type === "error") {
    const box = ui("message"); box.textContent = m.message; box.style.display = "block";
  } else if (m.type === "parameter" || m.type === "refused") {
    state.note = m.message; ui("note").textContent = m.message.replace(/^swirl view: /, "");
  }
}

// The surface's figures in the stats line, while it is on: the newest mesh and the server's time a mesh.
function surfaceText(m) {
  if (!state.surface || !state.mesh || !m.surface) return "";
  return ` · surface ${state.mesh.triangles} triangles, ${Number(m.surface.ms).toFixed(0)} ms a mesh`;
}

// ---- Replay: the time slider ------------------------------------------------------------
let scrubbing = false;
function setUpReplay(m) {
  ui("replay").style.display = "block";
  const slider = ui("slider"); slider.max = Math.max(0, m.frames - 1);
  // The live-only controls (the push, a simulation's single step) are hidden: < and > step frames here.
  ui("pushlabel").style.display = "none"; ui("push").checked = false;
  ui("step").style.display = "none"; ui("reset").textContent = "first";
  ui("help").textContent = "drag: orbit · shift+drag: pan · wheel: zoom · slider: any frame";
  const speed = ui("speed"); speed.innerHTML = "";
  for (const [v, t] of [[30, "30 frames/s"], [10, "10 frames/s"], [5, "5 frames/s"], [2, "2 frames/s"], [1, "1 frame/s"]]) {
    const o = document.createElement("option"); o.value = v; o.textContent = t; speed.appendChild(o);
  }
  speed.value = "10";
  ui("plot").style.display = "none";
}
let seek = null;  // the frame last asked for, until a status shows it
function sendSeek(i) {
  seek = { frame: i, at: performance.now() }; ui("slider").value = i;
  const b = new DataView(new ArrayBuffer(5)); b.setUint8(0, 8); b.setUint32(1, i, true); send(b.buffer);
}
function shownOrAsked() { return seek ? seek.frame : state.status ? state.status.frame : 0; }
ui("slider").addEventListener("pointerdown", () => { scrubbing = true; });
ui("slider").addEventListener("pointerup", () => { scrubbing = false; });
ui("slider").addEventListener("input", (e) => sendSeek(Number(e.target.value)));
ui("prev").onclick = () => { const f = shownOrAsked(); if (f > 0) sendSeek(f - 1); };
ui("next").onclick = () => { const f = shownOrAsked(); if (state.status && f + 1 < state.status.frames) sendSeek(f + 1); };

// ---- Live parameters: viscosity, gravity (strength and tilt), softening ----------------------
// A slider sends its value when released ("change"): one change, one line in swirl's log.
const sliders = {};  // by scene key: {spec, inputs, label}
function fmt(v) { return Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(2) : Number(v.toPrecision(3)).toString(); }
function setUpParameters(list) {
  const box = ui("params"); box.innerHTML = ""; box.style.display = list.length ? "block" : "none";
  for (const p of list) {
    const row = document.createElement("label"), text = document.createElement("span");
    const make = (min, max, value, step) => { const r = document.createElement("input"); r.type = "range";
      r.min = min; r.max = max; r.step = step; r.value = value; r.dataset.key = p.key; return r; };
    let inputs;
    if (p.vector) {  // strength |g| and the tilt from -z toward +x, in degrees
      const g = p.value, s = Math.hypot(g[0], g[1], g[2]);
      const tilt = s > 0 ? Math.atan2(g[0], -g[2]) * 180 / Math.PI : 0;
      inputs = [make(p.min, p.max, s, (p.max - p.min) / 200), make(-90, 90, Math.max(-90, Math.min(90, tilt)), 1)];
      inputs[0].id = "param-gravity"; inputs[1].id = "param-gravity-tilt";
      const send_g = () => { const s = Number(inputs[0].value), t = Number(inputs[1].value) * Math.PI / 180;
        sendParameter(p.id, [s * Math.sin(t), 0, -s * Math.cos(t)]); };
      inputs.forEach((r) => r.addEventListener("change", send_g));
    } else {
      inputs = [make(p.min, p.max, p.value, (p.max - p.min) / 200)];
      inputs[0].id = "param-" + p.label;
      inputs[0].addEventListener("change", () => sendParameter(p.id, [Number(inputs[0].value), 0, 0]));
    }
    inputs[0].title = `${p.key}: ${p.min} to ${p.max} ${p.unit}` + (p.vector ? " (|g|)" : "");
    if (p.vector) {
      inputs[1].title = "tilt of g from -z toward +x, degrees";
      const tilt = document.createElement("span"); tilt.textContent = " tilt ";
      row.append(text, inputs[0], tilt, inputs[1]);
    } else {
      row.append(text, ...inputs);
    }
    box.appendChild(row);
    sliders[p.key] = { spec: p, inputs, text };
  }
  const values = {}; for (const p of list) values[p.key] = p.value;
  showParameters(values);
}
function showParameters(values) {
  state.parameters = values;
  for (const [key, v] of Object.entries(values)) {
    const s = sliders[key]; if (!s) continue;
    const unit = s.spec.unit ? " " + s.spec.unit : "";
    s.text.textContent = s.spec.vector ? `${s.spec.label} (${v.map(fmt).join(", ")})${unit} ` : `${s.spec.label} ${fmt(v)}${unit} `;
    if (!s.spec.vector && document.activeElement !== s.inputs[0]) s.inputs[0].value = v;
  }
}
function sendParameter(id, v) {
  const b = new DataView(new ArrayBuffer(14)); b.setUint8(0, 9); b.setUint8(1, id);
  v.forEach((x, i) => b.setFloat32(2 + 4 * i, x, true)); send(b.buffer);
}
// The fluid's density error from a status's diagnostics (diagnostics.csv's columns): DFSPH's own
// average compression when it runs, else the mean |ρ − ρ0|/ρ0; undefined without a fluid.
function densityError(m) {
  const d = m.diagnostics || {};
  return Number.isFinite(d.dfsph_density_error) ? d.dfsph_density_error : d.mean_density_error;
}
// Three bands, each scaled to its own range over the last 240 statuses, labelled with the newest value.
function plot() {
  const c = ui("plot"), g = c.getContext("2d"); g.clearRect(0, 0, c.width, c.height);
  const h = state.history; if (h.length < 2) return;
  const band = (key, label, text, colour, y0) => {
    const y1 = y0 + 36, vs = h.map((x) => x[key]).filter(Number.isFinite);
    g.fillStyle = "#889";
    g.fillText(vs.length ? `${label} ${text(vs[vs.length - 1])}` : `${label}: none in this run`, 4, y0 - 2);
    if (!vs.length) return;
    const lo = Math.min(...vs), hi = Math.max(...vs), span = hi - lo || 1;
    g.strokeStyle = colour; g.beginPath();
    let first = true;
    h.forEach((x, i) => {
      if (!Number.isFinite(x[key])) return;
      const px = (i / (h.length - 1)) * c.width, py = y1 - ((x[key] - lo) / span) * (y1 - y0);
      first ? g.moveTo(px, py) : g.lineTo(px, py); first = false;
    });
    g.stroke();
  };
  band("e", "energy", (v) => v.toPrecision(4), "#6cf", 14);
  band("err", "density error", (v) => `${(100 * v).toPrecision(3)} %`, "#9e6", 66);
  band("rate", "steps/s", (v) => v.toFixed(1), "#fc6", 118);
}

// ---- Controls back ---------------------------------------------------------------
let socket = null;
function send(bytes) { if (socket && socket.readyState === 1) socket.send(bytes); }
function sendKind(k) { send(new Uint8Array([k])); }
function sendSpeed(s) { const b = new DataView(new ArrayBuffer(5)); b.setUint8(0, 5); b.setFloat32(1, s, true); send(b.buffer); }
function sendColour(i) { send(new Uint8Array([6, i])); }
function sendPush(point, velocity, on) {
  const b = new DataView(new ArrayBuffer(34)); b.setUint8(0, 7);
  const r = 10 * particleRadius(), values = [...point, ...velocity, r, 40];
  values.forEach((v, i) => b.setFloat32(1 + 4 * i, v, true));
  b.setUint8(33, on ? 1 : 0); send(b.buffer);
}
// The surface on or off: the box, the drawing, and (send) the server, which makes meshes only while someone wants them.
function setSurface(on, tell) {
  state.surface = on; ui("surface").checked = on;
  if (!on) state.mesh = null;  // a mesh kept from before would be stale when turned on again
  if (tell) send(new Uint8Array([10, on ? 1 : 0]));
}
function setPaused(p) { state.paused = p; ui("play").textContent = p ? "play" : "pause"; }
ui("play").onclick = () => { sendKind(state.paused ? 2 : 1); setPaused(!state.paused); };
ui("step").onclick = () => sendKind(3);
ui("reset").onclick = () => { sendKind(4); ui("message").style.display = "none"; };
ui("speed").onchange = (e) => sendSpeed(Number(e.target.value));
ui("colour").onchange = (e) => sendColour(Number(e.target.value));
ui("surface").onchange = (e) => setSurface(e.target.checked, true);

// ---- Mouse: orbit, pan, zoom, push -----------------------------------------------------
let drag = null;
function worldAt(x, y) {  // the point under the pointer on the plane through the target facing the camera
  const w = canvas.clientWidth, h = canvas.clientHeight, t = Math.tan(0.4);
  const { r, u, f } = basis(), e = eye();
  const dir = normalise([0, 1, 2].map((a) => f[a] + r[a] * ((2 * x / w - 1) * t * w / h) + u[a] * ((1 - 2 * y / h) * t)));
  const s = dot(sub(state.target, e), f) / dot(dir, f);
  return [e[0] + s * dir[0], e[1] + s * dir[1], e[2] + s * dir[2]];
}
canvas.addEventListener("pointerdown", (ev) => {
  canvas.setPointerCapture(ev.pointerId);
  drag = { x: ev.clientX, y: ev.clientY, pan: ev.shiftKey, push: ui("push").checked, t: performance.now(), p: worldAt(ev.clientX, ev.clientY) };
  if (drag.push) sendPush(drag.p, [0, 0, 0], true);
});
canvas.addEventListener("pointermove", (ev) => {
  if (!drag) return;
  const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
  if (drag.push) {
    const now = performance.now(), p = worldAt(ev.clientX, ev.clientY), dt = Math.max((now - drag.t) / 1000, 1e-3);
    sendPush(p, sub(p, drag.p).map((v) => v / dt), true);
    drag.p = p; drag.t = now;
  } else if (drag.pan) {
    const { r, u } = basis(), k = state.distance * 0.0015;
    state.target = [0, 1, 2].map((a) => state.target[a] - r[a] * dx * k + u[a] * dy * k);
  } else {
    state.yaw -= dx * 0.006; state.pitch = Math.max(-1.5, Math.min(1.5, state.pitch + dy * 0.006));
  }
  drag.x = ev.clientX; drag.y = ev.clientY;
});
canvas.addEventListener("pointerup", () => { if (drag && drag.push) sendPush(drag.p, [0, 0, 0], false); drag = null; });
canvas.addEventListener("wheel", (ev) => { ev.preventDefault(); state.distance *= Math.exp(ev.deltaY * 0.001); }, { passive: false });

// The colour bar.
(() => { const g = ui("bar").getContext("2d");
  for (let i = 0; i < 200; i++) { const t = 1 - i / 199;
    const r = Math.min(1, Math.max(0, 1.5 * t - 0.2)), gg = Math.min(1, Math.max(0, 1.6 * t * (1.3 - t) + 0.15)), b = Math.min(1, Math.max(0, 1 - 1.4 * t + 0.3));
    g.fillStyle = `rgb(${255 * r | 0},${255 * gg | 0},${255 * b | 0})`; g.fillRect(0, i, 16, 1); } })();

// ---- Connection ----------------------------------------------------------------------
function connect() {
  const url = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws` + (token ? `?token=${encodeURIComponent(token)}` : "");
  socket = new WebSocket(url); socket.binaryType = "arraybuffer";
  socket.onmessage = (ev) => {
    if (typeof ev.data === "string") return onText(ev.data);
    const magic = ev.data.byteLength >= 4 ? new DataView(ev.data).getUint32(0, true) : 0;
    if (magic === 0x4D565753) onMesh(ev.data);  // "SWVM"
    else onFrame(ev.data);                       // "SWVF" (checked there)
  };
  socket.onclose = () => { ui("stats").textContent = "disconnected: the run has ended (reload to reconnect)"; };
}
connect();
requestAnimationFrame(draw);
