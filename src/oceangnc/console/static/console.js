// oceangnc operator console: WebSocket client, map, gauges, stick (gamepad / keyboard / on-screen).
// Plain browser JavaScript, no build step. Coordinates are NED (north x, east y, metres);
// the map draws north up, east right. Stick: surge ahead positive, yaw to starboard positive.
"use strict";

const $ = (id) => document.getElementById(id);
// the session token comes with the URL printed by `oceangnc console` (/?token=...); kept for reloads
const TOKEN = new URLSearchParams(location.search).get("token") || sessionStorage.getItem("oceangnc-token") || "";
if (TOKEN) sessionStorage.setItem("oceangnc-token", TOKEN);
const S = {
  ws: null, role: null, client: null, operator: null, charts: [], hello: null, state: null, lastStateWall: 0, tracks: {}, route: [], draft: [],
  scenarioRoute: [], rejected: [], recent: [], events: [], rtt: null, gaugeEls: {}, readoutEls: {},
  view: { cx: 0, cy: 0, scale: 5, auto: true },
  stick: { surge: 0, yaw: 0, source: "none" },
  kb: { surge: 0, yaw: 0, keys: new Set() }, touch: null, padEstopPrev: false, pingId: 0,
};
// test and scripting hook (read-only use; sendRaw bypasses the page's own validation on purpose)
window.__console = S;
S.sendRaw = (text) => { if (S.ws && S.ws.readyState === 1) S.ws.send(text); };

function send(obj) {
  if (S.ws && S.ws.readyState === 1) { S.ws.send(JSON.stringify(obj)); return true; }
  return false;
}

// ---------------------------------------------------------------- connection
function connect() {
  const want = S.want = new URLSearchParams(location.search).get("role") === "viewer" ? "viewer" : "operator";
  const ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws?token=" +
    encodeURIComponent(TOKEN) + "&role=" + want);
  S.ws = ws;
  ws.onmessage = (ev) => {
    let m;
    try { m = JSON.parse(ev.data); } catch (e) { return; }
    if (m.type === "hello") onHello(m);
    else if (m.type === "state") onState(m);
    else if (m.type === "rejected") onRejected(m.reason);  // the server logs it once, as an event
    else if (m.type === "role") onRole(m);
    else if (m.type === "pong") { if (m.id === S.pingId) S.rtt = performance.now() - S.pingSent; }
  };
  ws.onclose = () => { S.ws = null; setTimeout(connect, 1000); };
}
setInterval(() => { S.pingId += 1; S.pingSent = performance.now(); send({ type: "ping", id: S.pingId }); }, 2000);

function onRole(m) {
  S.role = m.role; S.client = m.client; S.operator = m.operator;
  // a page opened to drive takes control as soon as nobody holds it (never from another operator)
  if (S.want === "operator" && m.role === "viewer" && m.operator == null) send({ type: "control", take: true });
  const el = $("role");
  el.textContent = m.role === "operator" ? `operator #${m.client}` : `viewer #${m.client}`;
  el.className = "lamp " + (m.role === "operator" ? "ok" : "warn");
  el.dataset.role = m.role;
  const btn = $("take");
  btn.textContent = m.role === "operator" ? "Release control" : m.operator == null ? "Take control" : `Take over from #${m.operator}`;
  document.body.classList.toggle("viewer", m.role !== "operator");
  for (const b of document.querySelectorAll("[data-cmd]")) b.disabled = m.role !== "operator";
}

function onRejected(reason) {
  S.rejected.push(reason);
  if (reason.startsWith("gains:")) {  // a refused gain goes back to the value the controller has
    for (const inp of document.querySelectorAll("#gains input")) { inp.value = inp.dataset.orig; inp.classList.remove("pending"); }
  }
}

function onHello(h) {
  S.hello = h;
  S.tracks = {};
  for (const [k, pts] of Object.entries(h.tracks || {})) S.tracks[k] = pts.slice();
  S.route = (h.view.route || []).slice();
  S.scenarioRoute = S.route.slice();
  S.draft = [];
  S.view.auto = true;
  $("scenario-name").textContent = h.scenario + " — " + h.summary;
  const sel = $("scenario-select");
  sel.innerHTML = "";
  for (const n of h.scenarios) {
    const o = document.createElement("option"); o.value = n; o.textContent = n; if (n === h.scenario) o.selected = true; sel.appendChild(o);
  }
  for (const id of ["loop-closed", "loop-open"]) {
    $(id).disabled = !h.loop_switch;
    if (!h.loop_switch) $(id).title = "this scenario fixes its controller in its config";
  }
  for (const id of ["route-send", "route-clear", "route-scenario"]) $(id).disabled = !h.route_edit;
  $("routehint").textContent = h.route_edit ? "Auto mode: click the map to add waypoints" : "this scenario flies a fixed route";
  buildReadouts(h.view.readouts || []);
  buildGauges(h.view.gauges || []);
  buildGains(h.gains || {});
  buildCharts(h);
}

function onState(st) {
  S.state = st;
  S.lastStateWall = performance.now();
  S.recent.push(st); if (S.recent.length > 200) S.recent.shift();
  if (st.waypoints) S.route = st.waypoints;
  for (const b of (S.hello ? S.hello.view.bodies : [])) {
    const x = st.signals[b.name + ".x"], y = st.signals[b.name + ".y"];
    if (x == null || y == null) continue;
    const tr = S.tracks[b.name] || (S.tracks[b.name] = []);
    const last = tr[tr.length - 1];
    if (!last || Math.hypot(last[0] - x, last[1] - y) > 0.05) { tr.push([x, y]); if (tr.length > 20000) tr.splice(0, 5000); }
  }
  if (st.events) for (const e of st.events) addEvent(e);
  pushCharts(st);
  updatePanels();
}

// ---------------------------------------------------------------- panels
function fmt(v, d = 2) { return v == null || !isFinite(v) ? "—" : Number(v).toFixed(d); }

function buildReadouts(list) {
  const box = $("readouts"); box.innerHTML = ""; S.readoutEls = {};
  for (const r of list) {
    const d = document.createElement("div"); d.className = "ro";
    d.innerHTML = `<div class="lbl"></div><span class="val">—</span><span class="unit"></span>`;
    d.querySelector(".lbl").textContent = r.label; d.querySelector(".unit").textContent = r.unit || "";
    d.dataset.key = r.key; box.appendChild(d); S.readoutEls[r.key] = { el: d.querySelector(".val"), spec: r };
  }
}

function buildGauges(list) {
  const box = $("gauges"); box.innerHTML = ""; S.gaugeEls = {};
  for (const g of list) {
    const d = document.createElement("div"); d.className = "gauge"; d.dataset.key = g.key;
    d.innerHTML = `<div class="lbl"><span></span><span class="gv">—</span></div><div class="bar"><div class="fill"></div><div class="zero"></div></div>`;
    d.querySelector(".lbl span").textContent = g.label;
    const lo = g.min, hi = g.max, z = (0 - lo) / (hi - lo);
    d.querySelector(".zero").style.left = (100 * Math.min(1, Math.max(0, z))) + "%";
    box.appendChild(d); S.gaugeEls[g.key] = { el: d, spec: g, z };
  }
}

function buildGains(gains) {
  const box = $("gains"); box.innerHTML = "";
  const names = Object.keys(gains);
  if (!names.length) { box.textContent = "this scenario exposes no adjustable gains"; return; }
  const tb = document.createElement("table");
  for (const n of names) {
    const g = gains[n]; const tr = document.createElement("tr");
    tr.innerHTML = `<td title=""></td><td><input type="number" step="any"></td><td class="u"></td>`;
    tr.children[0].textContent = n.replace(/^[^.]*\./, ""); tr.children[0].title = (g.description || "") + ` [${g.min} .. ${g.max}]`;
    const inp = tr.querySelector("input"); inp.value = g.value; inp.min = g.min; inp.max = g.max; inp.dataset.name = n; inp.dataset.orig = g.value;
    tr.children[2].textContent = g.unit || ""; tb.appendChild(tr);
  }
  box.appendChild(tb);
}

$("gains-apply").onclick = () => {
  const gains = {};
  for (const inp of document.querySelectorAll("#gains input")) {
    if (inp.value !== inp.dataset.orig) gains[inp.dataset.name] = Number(inp.value);
  }
  if (Object.keys(gains).length && send({ type: "gains", gains })) {
    for (const inp of document.querySelectorAll("#gains input")) if (inp.dataset.name in gains) inp.classList.add("pending");
  }
};

function addEvent(e, local) {
  const g = /^gain (\S+) = (\S+)/.exec(e.text || "");  // an applied gain: it is the box's value now
  if (g) for (const inp of document.querySelectorAll("#gains input")) if (inp.dataset.name === g[1]) { inp.dataset.orig = g[2]; inp.classList.remove("pending"); }
  const ol = $("events"); const li = document.createElement("li");
  li.className = e.level; li.textContent = `${fmt(e.t, 1)} s  ${e.text}`;
  ol.insertBefore(li, ol.firstChild);
  while (ol.children.length > 300) ol.removeChild(ol.lastChild);
  S.events.push(e);
}

function updatePanels() {
  const st = S.state; if (!st) return;
  const sig = st.signals;
  for (const [k, r] of Object.entries(S.readoutEls)) {
    let v = sig[k]; if (v != null) { v *= (r.spec.scale || 1); if (r.spec.wrap360) v = ((v % 360) + 360) % 360; }
    r.el.textContent = fmt(v, r.spec.unit === "deg" ? 1 : 2);
  }
  for (const [k, g] of Object.entries(S.gaugeEls)) {
    const s = g.spec; let v = sig[k]; const f = g.el.querySelector(".fill");
    if (v == null) { g.el.querySelector(".gv").textContent = "—"; f.style.width = "0"; continue; }
    v *= (s.scale || 1);
    const p = Math.min(1, Math.max(0, (v - s.min) / (s.max - s.min)));
    const a = Math.min(p, g.z), b = Math.max(p, g.z);
    f.style.left = (100 * a) + "%"; f.style.width = (100 * (b - a)) + "%"; f.classList.toggle("neg", v < 0);
    g.el.querySelector(".gv").textContent = `${fmt(v, 1)} ${s.unit || ""}`;
    g.el.dataset.value = v;
  }
  // buttons reflect the server's state
  $("mode-remote").classList.toggle("active", st.mode === "remote");
  $("mode-auto").classList.toggle("active", st.mode === "auto");
  $("loop-closed").classList.toggle("active", st.loop === "closed");
  $("loop-open").classList.toggle("active", st.loop === "open");
  $("pause").textContent = st.paused ? "Resume" : "Pause";
  $("estop").classList.toggle("engaged", st.estop);
  $("estop-reset").disabled = !st.estop || S.role !== "operator";
  const ban = $("banner");
  let text = "", cls = "";
  if (st.estop) text = "EMERGENCY STOP — thrust zero (latched)";
  else if (st.failsafe) text = `FAILSAFE: ${st.failsafe_reason} — ${S.hello && S.hello.station_keep ? "station-keeping" : "thrust zero"}`;
  else if (st.ended) { text = st.error ? "RUN ENDED: " + st.error : "RUN ENDED — start a new run"; cls = "ended"; }
  else if (st.paused) { text = "PAUSED"; cls = "paused"; }
  ban.textContent = text; ban.className = text ? cls : "hidden";
  ban.dataset.state = st.estop ? "estop" : st.failsafe ? "failsafe" : st.ended ? "ended" : st.paused ? "paused" : "";
  // sensors and link
  const sens = $("sensors"); sens.innerHTML = "";
  const lamp = (txt, ok, title) => { const s = document.createElement("span"); s.className = "lamp " + (ok === true ? "ok" : ok === false ? "bad" : "warn"); s.textContent = txt; if (title) s.title = title; sens.appendChild(s); return s; };
  const age = st.stick.age;
  lamp(`stick ${st.stick.source}${age != null ? " " + fmt(age, 1) + " s" : ""}`, st.mode !== "remote" ? null : (age != null && age < 1.0), "age of the last stick message at the server");
  lamp(st.ended ? "sim ended" : `sim ${fmt(st.rtf, 2)}× (target ${st.speed}×)`,
       st.paused || st.ended ? null : Math.abs(st.rtf - st.speed) < 0.1 * st.speed, "measured real-time factor");
  lamp(`RTT ${S.rtt == null ? "—" : fmt(S.rtt, 0) + " ms"}`, S.rtt == null ? null : S.rtt < 200);
  for (const s of (S.hello ? S.hello.view.sensors : [])) {
    const v = sig[s.key]; const ok = v != null && v >= 0.5;
    const el = lamp(`${s.label} ${ok ? "OK" : "FAIL"}`, ok, s.key); el.dataset.sensor = s.key;
  }
  $("mapinfo").textContent = `t = ${fmt(st.t, 1)} s   ${st.mode.toUpperCase()} / ${st.loop} loop   clients ${st.clients}` +
    `   operator ${st.operator == null ? "none" : "#" + st.operator}`;
  drawCharts();
}

function linkLamp() {
  const el = $("link");
  const fresh = S.ws && S.ws.readyState === 1 && performance.now() - S.lastStateWall < 1000;
  el.className = "lamp " + (fresh ? "ok" : "bad");
  el.textContent = fresh ? "link: up" : "link: down";
  el.dataset.up = fresh ? "1" : "0";
}
setInterval(linkLamp, 250);

// ---------------------------------------------------------------- buttons
$("mode-remote").onclick = () => send({ type: "mode", mode: "remote" });
$("mode-auto").onclick = () => send({ type: "mode", mode: "auto" });
$("loop-closed").onclick = () => send({ type: "loop", loop: "closed" });
$("loop-open").onclick = () => send({ type: "loop", loop: "open" });
$("pause").onclick = () => send({ type: "pause", paused: !(S.state && S.state.paused) });
$("estop").onclick = () => send({ type: "estop", engaged: true });
$("estop-reset").onclick = () => send({ type: "estop", engaged: false });
$("newrun").onclick = () => send({ type: "new_run", scenario: $("scenario-select").value });
$("route-send").onclick = () => { if (S.draft.length) { send({ type: "waypoints", points: S.draft }); S.draft = []; } };
$("route-clear").onclick = () => { S.draft = []; };
$("route-scenario").onclick = () => { if (S.scenarioRoute.length) send({ type: "waypoints", points: S.scenarioRoute }); };
$("fit").onclick = () => { S.view.auto = true; };
$("take").onclick = () => {
  if (S.role === "operator") send({ type: "control", take: false });
  else send({ type: "control", take: true, force: S.operator != null });  // explicit take-over, logged
};
$("download").href = "/api/log.parquet?token=" + encodeURIComponent(TOKEN);

// ---------------------------------------------------------------- strip charts (last 60 s)
const CHART_SPAN = 60;
const CHARTS = [
  { label: "UUV depth", unit: "m", fn: (g) => g["uuv.z"] },
  { label: "relative distance", unit: "m", fn: (g) => (g["usv.x"] == null || g["uuv.x"] == null ? null : Math.hypot(g["usv.x"] - g["uuv.x"], g["usv.y"] - g["uuv.y"])) },
  { label: "cable tension", unit: "N", fn: (g) => g["cable.top_tension"] },
];
function buildCharts(h) {
  const box = $("charts"); box.innerHTML = ""; S.charts = [];
  for (const c of CHARTS) {
    const d = document.createElement("div"); d.className = "chart";
    d.innerHTML = `<div class="lbl"><span></span><span class="cv">—</span></div><canvas width="340" height="54"></canvas>`;
    d.querySelector(".lbl span").textContent = `${c.label} [${c.unit}]`;
    box.appendChild(d);
    S.charts.push({ spec: c, el: d, cv: d.querySelector("canvas"), t: [], v: [], seen: false });
  }
}
function pushCharts(st) {
  for (const ch of S.charts) {
    const v = ch.spec.fn(st.signals);
    if (v == null || !isFinite(v)) continue;
    ch.seen = true;
    if (ch.t.length && st.t < ch.t[ch.t.length - 1]) { ch.t = []; ch.v = []; }
    ch.t.push(st.t); ch.v.push(v);
    while (ch.t.length && ch.t[0] < st.t - CHART_SPAN) { ch.t.shift(); ch.v.shift(); }
  }
}
function drawCharts() {
  let none = $("charts-none");
  if (!none) { none = document.createElement("div"); none.id = "charts-none"; none.className = "muted";
    none.textContent = "no UUV depth, USV-UUV distance or cable tension in this scenario"; $("charts").appendChild(none); }
  none.classList.toggle("hidden", S.charts.some((c) => c.seen));
  for (const ch of S.charts) {
    ch.el.classList.toggle("hidden", !ch.seen);
    if (!ch.seen || !ch.t.length) continue;
    const c = ch.cv.getContext("2d"), W = ch.cv.width, H = ch.cv.height;
    c.fillStyle = "#0d1a26"; c.fillRect(0, 0, W, H);
    let lo = Math.min(...ch.v), hi = Math.max(...ch.v);
    if (hi - lo < 1e-6) { lo -= 0.5; hi += 0.5; }
    const pad = 0.08 * (hi - lo); lo -= pad; hi += pad;
    const t1 = ch.t[ch.t.length - 1], t0 = t1 - CHART_SPAN;
    c.strokeStyle = "#3aa0ff"; c.lineWidth = 1.5; c.beginPath();
    ch.t.forEach((t, i) => { const x = (t - t0) / CHART_SPAN * W, y = H - (ch.v[i] - lo) / (hi - lo) * H; if (i) c.lineTo(x, y); else c.moveTo(x, y); });
    c.stroke();
    c.fillStyle = "#8fa3b8"; c.font = "10px monospace";
    c.fillText(hi.toFixed(2), 2, 10); c.fillText(lo.toFixed(2), 2, H - 2); c.fillText("-60 s", W - 34, H - 2);
    ch.el.querySelector(".cv").textContent = ch.v[ch.v.length - 1].toFixed(2);
  }
}

// ---------------------------------------------------------------- stick input
const KEYMAP = { ArrowUp: ["surge", 1], KeyW: ["surge", 1], ArrowDown: ["surge", -1], KeyS: ["surge", -1],
  ArrowLeft: ["yaw", -1], KeyA: ["yaw", -1], ArrowRight: ["yaw", 1], KeyD: ["yaw", 1] };
function typing(e) { const t = e.target; return t && (t.tagName === "INPUT" || t.tagName === "SELECT" || t.tagName === "TEXTAREA"); }
window.addEventListener("keydown", (e) => {
  if (typing(e)) return;
  if (e.code === "Space") { e.preventDefault(); send({ type: "estop", engaged: true }); return; }
  if (KEYMAP[e.code]) { e.preventDefault(); S.kb.keys.add(e.code); }
});
window.addEventListener("keyup", (e) => { S.kb.keys.delete(e.code); });
window.addEventListener("blur", () => { S.kb.keys.clear(); });

function pollGamepad() {
  // poll; never rely on `instanceof Gamepad` (test pads and some drivers are plain objects)
  const pads = navigator.getGamepads ? navigator.getGamepads() : [];
  for (const p of pads || []) {
    if (p && p.connected !== false && p.axes && p.axes.length >= 2) return p;
  }
  return null;
}
const dead = (v, d = 0.08) => (Math.abs(v) < d ? 0 : Math.sign(v) * (Math.abs(v) - d) / (1 - d));
const clamp1 = (v) => Math.max(-1, Math.min(1, v));
const pressed = (b) => (b == null ? false : typeof b === "object" ? !!(b.pressed || b.value > 0.5) : b > 0.5);

let lastTick = performance.now();
function inputTick() {
  const now = performance.now(), dt = Math.min(0.2, (now - lastTick) / 1000); lastTick = now;
  // keyboard: ramp toward the held direction at 2/s, back to zero at 4/s
  for (const ax of ["surge", "yaw"]) {
    let target = 0;
    for (const k of S.kb.keys) if (KEYMAP[k] && KEYMAP[k][0] === ax) target += KEYMAP[k][1];
    target = clamp1(target);
    const cur = S.kb[ax], rate = target === 0 ? 4 : 2;
    S.kb[ax] = cur + Math.max(-rate * dt, Math.min(rate * dt, target - cur));
  }
  const pad = pollGamepad();
  let src = "none", surge = 0, yaw = 0;
  if (S.touch) { src = "touch"; surge = S.touch.surge; yaw = S.touch.yaw; }
  else if (S.kb.keys.size || Math.abs(S.kb.surge) > 1e-3 || Math.abs(S.kb.yaw) > 1e-3) { src = "keyboard"; surge = S.kb.surge; yaw = S.kb.yaw; }
  else if (pad) { src = "gamepad"; surge = dead(-pad.axes[1]); yaw = dead(pad.axes[0]); }
  if (pad) {
    const b = pressed(pad.buttons && pad.buttons[1]);
    if (b && !S.padEstopPrev) send({ type: "estop", engaged: true });
    S.padEstopPrev = b;
  }
  S.stick = { surge: clamp1(surge), yaw: clamp1(yaw), source: src, pad: pad ? (pad.id || "gamepad") : null };
  $("stick-src").textContent = src + (pad ? ` (${pad.id || "pad"})` : "");
  $("stick-val").innerHTML = `surge ${fmt(S.stick.surge)}<br>yaw ${fmt(S.stick.yaw)}`;
  if (S.state && S.state.mode === "remote" && S.role === "operator") {
    send({ type: "stick", surge: S.stick.surge, yaw: S.stick.yaw, source: src });
  }
  drawStick();
}
setInterval(inputTick, 50);  // 20 Hz: the server's watchdog trips after 1 s without a stick message

const stickCv = $("stick");
function stickFromEvent(e) {
  const r = stickCv.getBoundingClientRect(), R = r.width / 2 - 12;
  let dx = (e.clientX - r.left - r.width / 2) / R, dy = (e.clientY - r.top - r.height / 2) / R;
  const m = Math.hypot(dx, dy); if (m > 1) { dx /= m; dy /= m; }
  return { surge: -dy, yaw: dx };
}
stickCv.addEventListener("pointerdown", (e) => { stickCv.setPointerCapture(e.pointerId); S.touch = stickFromEvent(e); });
stickCv.addEventListener("pointermove", (e) => { if (S.touch) S.touch = stickFromEvent(e); });
const release = () => { S.touch = null; };
stickCv.addEventListener("pointerup", release); stickCv.addEventListener("pointercancel", release);

function drawStick() {
  const c = stickCv.getContext("2d"), W = stickCv.width, R = W / 2 - 12;
  c.clearRect(0, 0, W, W);
  c.strokeStyle = "#35506b"; c.lineWidth = 1;
  c.beginPath(); c.arc(W / 2, W / 2, R, 0, 2 * Math.PI); c.stroke();
  c.beginPath(); c.moveTo(W / 2, 12); c.lineTo(W / 2, W - 12); c.moveTo(12, W / 2); c.lineTo(W - 12, W / 2); c.stroke();
  const x = W / 2 + S.stick.yaw * R, y = W / 2 - S.stick.surge * R;
  c.fillStyle = S.state && S.state.mode === "remote" ? "#3aa0ff" : "#5a6b7c";
  c.beginPath(); c.arc(x, y, 11, 0, 2 * Math.PI); c.fill();
}

// ---------------------------------------------------------------- map
const cv = $("map");
const BODY_COLORS = ["#4fc3f7", "#ffb74d", "#aed581", "#f48fb1"];
function resize() {
  const r = cv.getBoundingClientRect(), d = window.devicePixelRatio || 1;
  cv.width = Math.max(10, Math.round(r.width * d)); cv.height = Math.max(10, Math.round(r.height * d));
}
window.addEventListener("resize", resize);
const toScreen = (n, e) => [cv.width / 2 + (e - S.view.cy) * S.view.scale, cv.height / 2 - (n - S.view.cx) * S.view.scale];
S.toScreen = (n, e) => toScreen(n, e);
const toWorld = (px, py) => [S.view.cx - (py - cv.height / 2) / S.view.scale, S.view.cy + (px - cv.width / 2) / S.view.scale];

function fitView() {
  let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  const add = (p) => { if (p && isFinite(p[0]) && isFinite(p[1])) { lo = [Math.min(lo[0], p[0]), Math.min(lo[1], p[1])]; hi = [Math.max(hi[0], p[0]), Math.max(hi[1], p[1])]; } };
  S.route.forEach(add); S.draft.forEach(add);
  for (const pl of (S.hello ? S.hello.view.polylines : [])) pl.points.forEach(add);
  for (const tr of Object.values(S.tracks)) { const step = Math.max(1, Math.floor(tr.length / 500)); for (let i = 0; i < tr.length; i += step) add(tr[i]); if (tr.length) add(tr[tr.length - 1]); }
  if (S.state) for (const b of S.hello.view.bodies) add([S.state.signals[b.name + ".x"], S.state.signals[b.name + ".y"]]);
  if (!isFinite(lo[0])) { lo = [-10, -10]; hi = [10, 10]; }
  // fit north span into the height and east span into the width, with a 40 px margin all round
  const m = 40 * (window.devicePixelRatio || 1);
  S.view.cx = (lo[0] + hi[0]) / 2; S.view.cy = (lo[1] + hi[1]) / 2;
  S.view.scale = Math.max(1e-6, Math.min((cv.height - 2 * m) / Math.max(hi[0] - lo[0], 10),
                                         (cv.width - 2 * m) / Math.max(hi[1] - lo[1], 10)));
}

function niceStep(px) { const w = px / S.view.scale, p = Math.pow(10, Math.floor(Math.log10(w))); for (const m of [1, 2, 5, 10]) if (m * p >= w) return m * p; return 10 * p; }

function drawGrid(c) {
  const step = niceStep(80 * (window.devicePixelRatio || 1));
  const [n0, e0] = toWorld(0, cv.height), [n1, e1] = toWorld(cv.width, 0);
  c.strokeStyle = "#17405c"; c.lineWidth = 1; c.fillStyle = "#4d7a99"; c.font = `${11 * (window.devicePixelRatio || 1)}px monospace`;
  for (let e = Math.ceil(e0 / step) * step; e <= e1; e += step) { const [x] = toScreen(0, e); c.beginPath(); c.moveTo(x, 0); c.lineTo(x, cv.height); c.stroke(); c.fillText(`${+e.toFixed(3)} m E`, x + 3, cv.height - 6); }
  for (let n = Math.ceil(n0 / step) * step; n <= n1; n += step) { const [, y] = toScreen(n, 0); c.beginPath(); c.moveTo(0, y); c.lineTo(cv.width, y); c.stroke(); c.fillText(`${+n.toFixed(3)} m N`, 4, y - 3); }
  // north arrow
  const d = window.devicePixelRatio || 1, x = cv.width - 30 * d, y = 50 * d;
  c.fillStyle = "#cfe3f5"; c.beginPath(); c.moveTo(x, y - 18 * d); c.lineTo(x - 7 * d, y); c.lineTo(x + 7 * d, y); c.fill();
  c.fillText("N", x - 4 * d, y + 14 * d);
}

function polyline(c, pts, color, width, dash) {
  if (!pts || pts.length < 2) return;
  c.strokeStyle = color; c.lineWidth = width; c.setLineDash(dash || []);
  c.beginPath(); pts.forEach((p, i) => { const [x, y] = toScreen(p[0], p[1]); if (i) c.lineTo(x, y); else c.moveTo(x, y); }); c.stroke(); c.setLineDash([]);
}

function drawBody(c, b, color, idx = 0) {
  const sig = S.state.signals, n = sig[b.name + ".x"], e = sig[b.name + ".y"];
  if (n == null || e == null) return;
  const psi = sig[b.name + ".psi"] || 0, d = window.devicePixelRatio || 1;
  let L = b.length || 2, B = b.beam || L / 3;
  const minPx = 18 * d; let k = 1;
  if (L * S.view.scale < minPx) k = minPx / (L * S.view.scale);
  L *= k; B *= k;
  const shape = b.shape === "sub" ? [[0.5, 0], [0.35, 0.5], [-0.45, 0.5], [-0.5, 0], [-0.45, -0.5], [0.35, -0.5]]
    : [[0.5, 0], [0.2, 0.5], [-0.5, 0.5], [-0.5, -0.5], [0.2, -0.5]];
  const cps = Math.cos(psi), sps = Math.sin(psi);
  c.fillStyle = color; c.strokeStyle = "#fff"; c.lineWidth = 1.5 * d;
  c.beginPath();
  shape.forEach(([bx, by], i) => { const x = bx * L, y = by * B; const [sx, sy] = toScreen(n + x * cps - y * sps, e + x * sps + y * cps); if (i) c.lineTo(sx, sy); else c.moveTo(sx, sy); });
  c.closePath(); c.fill(); c.stroke();
  const [sx, sy] = toScreen(n, e);
  // labels stacked per body (USV above, UUV below, ...) so two vehicles close together stay readable
  const ly = sy - 10 * d + idx * 28 * d;
  c.save(); c.shadowColor = "#000"; c.shadowBlur = 4 * d;  // readable over a hull or a track
  c.fillStyle = "#fff"; c.font = `${11 * d}px sans-serif`; c.fillText(b.label || b.name, sx + 14 * d, ly);
  const z = sig[b.name + ".z"]; if (z != null && b.shape === "sub") c.fillText(`${z.toFixed(2)} m`, sx + 14 * d, ly + 13 * d);
  c.restore();
}

function drawCable(c) {
  const v = S.hello.view, sig = S.state.signals;
  if (v.cable && v.cable.x) {
    const pts = v.cable.x.map((k, i) => [sig[k], sig[v.cable.y[i]]]).filter((p) => p[0] != null && p[1] != null);
    polyline(c, pts, "#ffe082", 2 * (window.devicePixelRatio || 1));
    return;
  }
  const names = v.bodies.map((b) => b.name);
  if (names.includes("usv") && names.includes("uuv")) {
    polyline(c, [[sig["usv.x"], sig["usv.y"]], [sig["uuv.x"], sig["uuv.y"]]], "#ffe082", 2, [4, 3]);
  }
}

function draw() {
  requestAnimationFrame(draw);
  { const r = cv.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;  // the banner changes the height
    if (cv.width !== Math.max(10, Math.round(r.width * dpr)) || cv.height !== Math.max(10, Math.round(r.height * dpr))) resize(); }
  const c = cv.getContext("2d");
  c.fillStyle = "#0b2538"; c.fillRect(0, 0, cv.width, cv.height);
  if (!S.hello || !S.state) return;
  if (S.view.auto) fitView();
  drawGrid(c);
  const d = window.devicePixelRatio || 1;
  for (const pl of S.hello.view.polylines) {
    const style = { berth: ["#d7a15b", 4 * d, []], channel: ["#80cbc4", 2 * d, [8, 5]], shore: ["#a1887f", 3 * d, []], route: ["#9fa8da", 1.5 * d, [6, 4]] }[pl.style] || ["#ccc", 1.5 * d, []];
    polyline(c, pl.points, style[0], style[1], style[2]);
  }
  // route with the waypoint being steered to highlighted
  const wpi = S.state.signals["guidance.wp_index"];
  polyline(c, S.route, "#c5cae9", 1.2 * d, [6, 4]);
  S.route.forEach((p, i) => { const [x, y] = toScreen(p[0], p[1]); c.fillStyle = i === wpi ? "#ffeb3b" : "#c5cae9"; c.fillRect(x - 4 * d, y - 4 * d, 8 * d, 8 * d); });
  polyline(c, S.draft, "#ff9800", 1.5 * d, [3, 3]);
  S.draft.forEach((p, i) => { const [x, y] = toScreen(p[0], p[1]); c.fillStyle = "#ff9800"; c.beginPath(); c.arc(x, y, 5 * d, 0, 6.3); c.fill(); c.fillText(String(i + 1), x + 7 * d, y - 6 * d); });
  S.hello.view.bodies.forEach((b, i) => polyline(c, S.tracks[b.name], BODY_COLORS[i % 4] + "aa", 1.5 * d));
  drawCable(c);
  S.hello.view.bodies.forEach((b, i) => drawBody(c, b, BODY_COLORS[i % 4], i));
}
requestAnimationFrame(draw);

// zoom (wheel), pan (drag), add a waypoint (click, auto mode)
let drag = null;
cv.addEventListener("wheel", (e) => {
  e.preventDefault(); S.view.auto = false;
  const d = window.devicePixelRatio || 1, r = cv.getBoundingClientRect();
  const px = (e.clientX - r.left) * d, py = (e.clientY - r.top) * d;
  const [n, ea] = toWorld(px, py); const f = Math.exp(-e.deltaY * 0.0015);
  S.view.scale *= f; const [n2, e2] = toWorld(px, py); S.view.cx += n - n2; S.view.cy += ea - e2;
}, { passive: false });
cv.addEventListener("mousedown", (e) => { drag = { x: e.clientX, y: e.clientY, moved: false }; });
cv.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const d = window.devicePixelRatio || 1, dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
  if (drag.moved) { S.view.auto = false; S.view.cy -= dx * d / S.view.scale; S.view.cx += dy * d / S.view.scale; drag.x = e.clientX; drag.y = e.clientY; }
});
cv.addEventListener("mouseup", (e) => {
  if (drag && !drag.moved && S.state && S.state.mode === "auto" && S.hello && S.hello.route_edit) {
    const d = window.devicePixelRatio || 1, r = cv.getBoundingClientRect();
    const [n, ea] = toWorld((e.clientX - r.left) * d, (e.clientY - r.top) * d);
    S.draft.push([Math.round(n * 10) / 10, Math.round(ea * 10) / 10]);
  }
  drag = null;
});

resize();
connect();
