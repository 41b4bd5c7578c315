// The live view's page script (served by marsala-monitor serve; plain JS, no libraries).
// It polls /api/state (one request at a time, so a slow page never queues updates), draws the terrain picture
// (/api/terrain.png?v=N, fetched again only when its version changes) and the overlays on a canvas, and fills the
// side panel. World coordinates are metres, x east, y north; the picture covers the grid exactly, north up.
'use strict';

const POLL_MS = 200;
const TRAIL_POINTS = 400;
const ROLE_COLOURS = {
  active: '#ffd600', following: '#00e5ff', returning: '#e040fb', done: '#76ff03', dropped: '#757575',
  waiting: '#ffffff',
};
const ROLE_TEXT = {
  active: 'surveys, advances, builds or retreats at its front', following: 'follows, holds or backs off in the pipeline',
  returning: 'returns to the base to refill', done: 'at its goal or done', dropped: 'dropped by the world',
  waiting: 'no state yet',
};

const canvas = document.getElementById('map');
const ctx = canvas.getContext('2d');
const $ = (id) => document.getElementById(id);

let state = null;          // the latest /api/state document
let terrain = null;        // {image, version}
let terrainLoading = 0;    // version being fetched
const trails = new Map();  // agent id -> [[x, y], ...]
let trailRun = '';
let view = null;           // {x0, y0, x1, y1, scale, ox, oy}: world box and its placement on the canvas
let framing = 'action';    // 'action': what is going on (robots, base, targets, goal); 'terrain': all of it;
let custom = null;         // 'custom': this world box, after a wheel zoom or a drag

function fmt(v, digits) { return (v === undefined || v === null || Number.isNaN(v)) ? '-' : Number(v).toFixed(digits); }
function text(id, value) { const e = $(id); if (e.textContent !== String(value)) e.textContent = value; }
function paletteColour(id) {
  const p = (state && state.palette && state.palette.length) ? state.palette : ['#e6194b'];
  return p[(id - 1) % p.length];
}
function escapeHtml(s) {
  return String(s).replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);
}

async function poll() {
  try {
    const response = await fetch('/api/state', { cache: 'no-store' });
    if (!response.ok) throw new Error('HTTP ' + response.status);
    update(await response.json());
    $('connection').className = 'dot ok';
  } catch (e) {
    $('connection').className = 'dot bad';
  }
  setTimeout(poll, POLL_MS);
}

function update(s) {
  state = s;
  const run = s.run;
  text('source', s.source || '');
  if (run) {
    if (run.run_id !== trailRun) { trails.clear(); trailRun = run.run_id; }
    text('scenario', run.scenario);
    text('run-id', 'run ' + run.run_id);
    let phase = run.phase;
    if (!s.replay && run.running && run.status_age_s > 3) phase = 'stale';
    const p = $('phase');
    p.className = 'phase phase-' + phase;
    text('phase', phase === 'stale' ? 'no status ' + fmt(run.status_age_s, 0) + ' s' : phase);
    text('step', run.step);
    text('rate', fmt(run.steps_per_s, run.steps_per_s >= 100 ? 0 : 1));
    text('wall', fmt(run.wall_s, 1) + ' s');
    text('deposited', fmt(run.deposited_m3, 2) + ' m³');
    text('progress-label', s.replay ? 'replayed' : 'progress');
    text('progress', fmt(100 * run.progress, 0) + ' %');
    $('progress-bar').style.width = (100 * Math.max(0, Math.min(1, run.progress))) + '%';
    text('progress-detail', run.progress_detail || '');
    document.title = 'MARSala · ' + run.scenario + ' · step ' + run.step;
  }
  updateAgents(s.agents || []);
  updateEvents(s.events || []);
  updateScene(s);
  for (const a of s.agents || []) {
    if (!a.alive) continue;
    let t = trails.get(a.id);
    if (!t) { t = []; trails.set(a.id, t); }
    const last = t[t.length - 1];
    if (!last || last[0] !== a.x || last[1] !== a.y) t.push([a.x, a.y]);
    if (t.length > TRAIL_POINTS) t.splice(0, t.length - TRAIL_POINTS);
  }
  const m = s.map;
  if (m && (!terrain || terrain.version !== m.version) && terrainLoading !== m.version) {
    terrainLoading = m.version;
    const img = new Image();
    img.onload = () => { terrain = { image: img, version: m.version }; terrainLoading = 0; draw(); };
    img.onerror = () => { terrainLoading = 0; };
    img.src = '/api/terrain.png?v=' + m.version;
  }
  $('map-note').textContent = s.map_note || '';
  draw();
}

function updateAgents(agents) {
  text('robot-count', agents.length);
  const live = agents.filter((a) => a.alive).length;
  text('robot-live', '(' + live + ' live)');
  const rows = agents.map((a) => {
    const role = a.role;
    return '<tr class="agent-row' + (a.alive ? '' : ' dropped') + '" data-id="' + a.id + '" data-role="' + role + '"' +
      ' title="' + escapeHtml(a.name) + ' at (' + fmt(a.x, 2) + ', ' + fmt(a.y, 2) + ', ' + fmt(a.z, 2) + ') m">' +
      '<td><span class="swatch" style="background:' + paletteColour(a.id) + '"></span></td>' +
      '<td>' + a.id + '</td>' +
      '<td><span class="role" style="background:' + ROLE_COLOURS[role] + '">' + role + '</span></td>' +
      '<td>' + escapeHtml(a.state || '?') + (a.at_goal ? ' ★' : '') + '</td>' +
      '<td>' + fmt(a.material_m3, 2) + '</td>' +
      '<td>' + fmt(a.deposited_m3, 2) + '</td>' +
      '<td>' + a.accepted + '/' + a.rejected + '/' + a.missed + '</td></tr>';
  }).join('');
  const body = $('agents');
  if (body.dataset.html !== rows) { body.innerHTML = rows; body.dataset.html = rows; }
  const legend = Object.keys(ROLE_COLOURS).map((r) =>
    '<span title="' + ROLE_TEXT[r] + '"><span class="key" style="background:' + ROLE_COLOURS[r] + '"></span>' + r +
    '</span>').join('');
  const l = $('role-legend');
  if (l.dataset.html !== legend) { l.innerHTML = legend; l.dataset.html = legend; }
}

function updateEvents(events) {
  const html = events.map((e) => '<li><b>' + e.step + '</b> ' + (e.agent ? 'agent ' + e.agent : 'world') + ' ' +
    escapeHtml(e.kind) + (e.kind === 'deposited' ? ' ' + Number(e.volume_m3).toPrecision(3) + ' m³' : '') +
    (e.detail ? ' · ' + escapeHtml(e.detail) : '') + '</li>').join('');
  const list = $('events');
  if (list.dataset.html !== html) { list.innerHTML = html; list.dataset.html = html; }
}

function updateScene(s) {
  const m = s.map;
  const info = $('terrain-info');
  if (m) {
    info.textContent = m.cols + ' × ' + m.rows + ' cells of ' + m.cell_size_m + ' m (' + fmt(m.width_m, 1) + ' × ' +
      fmt(m.height_m, 1) + ' m), heights ' + fmt(m.min_height_m, 2) + ' to ' + fmt(m.max_height_m, 2) +
      ' m; deposits of ' + m.log_steps + ' steps, tinted by robot';
    info.dataset.version = m.version;
  } else {
    info.textContent = s.map_note || 'no terrain';
  }
  const items = [['#ffffff', 'base'], ['#ffffff', '× targets']];
  const scene = m && m.scene;
  if (scene && scene.goal) items.push(['#ffffff', '▭ goal']);
  if (scene && scene.site) items.push(['#ffd600', '▭ site']);
  if (scene && scene.payload) items.push(['#ff5252', '◆ payload start / destination']);
  const html = items.map(([c, t]) => '<span><span class="key" style="background:' + c + '"></span>' + t + '</span>')
    .join('');
  const l = $('scene-legend');
  if (l.dataset.html !== html) { l.innerHTML = html; l.dataset.html = html; }
}

// ---- drawing --------------------------------------------------------------------------------------------------

function terrainBox() {
  const m = state && state.map;
  return m ? { x0: m.xll, y0: m.yll, x1: m.xll + m.width_m, y1: m.yll + m.height_m } : null;
}

// Robots, base, targets, goal, site and payload, with a margin: where the run happens.
function actionBox() {
  const pts = [];
  for (const a of (state && state.agents) || []) pts.push([a.x, a.y]);
  const scene = state && state.map && state.map.scene;
  if (scene) {
    const b = scene.base;
    pts.push([b.x - b.r, b.y - b.r], [b.x + b.r, b.y + b.r]);
    for (const t of scene.targets) pts.push([t.x, t.y]);
    for (const r of [scene.goal, scene.site]) if (r) pts.push([r.x0, r.y0], [r.x1, r.y1]);
    if (scene.payload) pts.push(scene.payload.from, scene.payload.to);
  }
  if (!pts.length) return null;
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (const [x, y] of pts) { x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y); }
  const margin = Math.max(4, 0.25 * Math.max(x1 - x0, y1 - y0));
  return { x0: x0 - margin, y0: y0 - margin, x1: x1 + margin, y1: y1 + margin };
}

function worldBox() {
  if (framing === 'custom' && custom) return custom;
  const whole = terrainBox();
  const action = actionBox();
  if (!whole) return action || { x0: 0, y0: 0, x1: 20, y1: 20 };
  if (framing === 'terrain' || !action) return whole;
  // Zoom in only when what happens covers a small part of the terrain.
  const area = (b) => (b.x1 - b.x0) * (b.y1 - b.y0);
  if (area(action) > 0.35 * area(whole)) return whole;
  return { x0: Math.max(whole.x0, action.x0), y0: Math.max(whole.y0, action.y0),
           x1: Math.min(whole.x1, action.x1), y1: Math.min(whole.y1, action.y1) };
}

function setFraming(f) {
  framing = f;
  if (f !== 'custom') custom = null;
  for (const b of document.querySelectorAll('#framing button')) b.classList.toggle('on', b.dataset.framing === f);
  draw();
}

function toCanvas(x, y) { return [view.ox + (x - view.x0) * view.scale, view.oy + (view.y1 - y) * view.scale]; }

function draw() {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
  }
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.fillStyle = '#0e1014';
  ctx.fillRect(0, 0, w, h);
  if (!state) return;
  const box = worldBox();
  const pad = 16;
  const scale = Math.min((w - 2 * pad) / (box.x1 - box.x0), (h - 2 * pad) / (box.y1 - box.y0));
  view = { x0: box.x0, y0: box.y0, x1: box.x1, y1: box.y1, scale: scale,
           ox: (w - scale * (box.x1 - box.x0)) / 2, oy: (h - scale * (box.y1 - box.y0)) / 2 };
  const m = state.map;
  ctx.save();
  ctx.beginPath();
  ctx.rect(view.ox, view.oy, scale * (box.x1 - box.x0), scale * (box.y1 - box.y0));
  ctx.clip();
  if (m && terrain) {
    ctx.imageSmoothingEnabled = scale * m.cell_size_m * m.cols / m.image_width_px < 3;  // crisp cells when zoomed in
    const [ix, iy] = toCanvas(m.xll, m.yll + m.height_m);
    ctx.drawImage(terrain.image, ix, iy, scale * m.width_m, scale * m.height_m);
  } else {
    drawGrid(box);
  }
  if (m && m.scene) drawScene(m.scene);
  drawTrails();
  drawRobots();
  ctx.restore();
  drawScaleBar(w, h);
}

function drawGrid(box) {
  ctx.strokeStyle = '#232830';
  ctx.lineWidth = 1;
  const step = Math.pow(10, Math.floor(Math.log10(Math.max(box.x1 - box.x0, 1))));
  for (let x = Math.ceil(box.x0 / step) * step; x <= box.x1; x += step) {
    const [px] = toCanvas(x, 0);
    ctx.beginPath(); ctx.moveTo(px, view.oy); ctx.lineTo(px, view.oy + (box.y1 - box.y0) * view.scale); ctx.stroke();
  }
  for (let y = Math.ceil(box.y0 / step) * step; y <= box.y1; y += step) {
    const [, py] = toCanvas(0, y);
    ctx.beginPath(); ctx.moveTo(view.ox, py); ctx.lineTo(view.ox + (box.x1 - box.x0) * view.scale, py); ctx.stroke();
  }
}

function label(textValue, x, y, colour) {
  ctx.font = '600 12px system-ui, sans-serif';
  ctx.lineWidth = 3;
  ctx.strokeStyle = 'rgba(0,0,0,0.75)';
  ctx.strokeText(textValue, x, y);
  ctx.fillStyle = colour || '#fff';
  ctx.fillText(textValue, x, y);
}

function rect(r, colour, name) {
  const [ax, ay] = toCanvas(r.x0, r.y1);
  const [bx, by] = toCanvas(r.x1, r.y0);
  ctx.setLineDash([8, 5]);
  ctx.lineWidth = 2;
  ctx.strokeStyle = 'rgba(0,0,0,0.6)';
  ctx.strokeRect(ax + 1, ay + 1, bx - ax, by - ay);
  ctx.strokeStyle = colour;
  ctx.strokeRect(ax, ay, bx - ax, by - ay);
  ctx.setLineDash([]);
  label(name, ax + 5, ay + 15, colour);
}

function diamond(x, y, r, colour) {
  const [px, py] = toCanvas(x, y);
  ctx.beginPath();
  ctx.moveTo(px, py - r); ctx.lineTo(px + r, py); ctx.lineTo(px, py + r); ctx.lineTo(px - r, py); ctx.closePath();
  ctx.fillStyle = colour; ctx.fill();
  ctx.lineWidth = 2; ctx.strokeStyle = '#000'; ctx.stroke();
}

function drawScene(scene) {
  if (scene.goal) rect(scene.goal, '#ffffff', 'goal');
  if (scene.site) rect(scene.site, '#ffd600', 'site');
  if (scene.payload) {
    const [ax, ay] = toCanvas(scene.payload.from[0], scene.payload.from[1]);
    const [bx, by] = toCanvas(scene.payload.to[0], scene.payload.to[1]);
    ctx.setLineDash([4, 6]); ctx.lineWidth = 2; ctx.strokeStyle = 'rgba(255,82,82,0.8)';
    ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(bx, by); ctx.stroke(); ctx.setLineDash([]);
    diamond(scene.payload.from[0], scene.payload.from[1], 8, '#ff5252');
    diamond(scene.payload.to[0], scene.payload.to[1], 8, '#ff5252');
    label('payload', ax + 10, ay - 8, '#ff8a80');
    label('destination', bx + 10, by - 8, '#ff8a80');
  }
  const b = scene.base;
  const [bx, by] = toCanvas(b.x, b.y);
  ctx.beginPath(); ctx.arc(bx, by, Math.max(6, b.r * view.scale), 0, 2 * Math.PI);
  ctx.fillStyle = 'rgba(255,255,255,0.18)'; ctx.fill();
  ctx.lineWidth = 2; ctx.strokeStyle = '#fff'; ctx.stroke();
  label('base', bx - 14, by - Math.max(6, b.r * view.scale) - 6);
  for (const t of scene.targets) {
    const [tx, ty] = toCanvas(t.x, t.y);
    const r = 5;
    ctx.lineWidth = 4; ctx.strokeStyle = '#000';
    ctx.beginPath(); ctx.moveTo(tx - r, ty - r); ctx.lineTo(tx + r, ty + r); ctx.moveTo(tx + r, ty - r);
    ctx.lineTo(tx - r, ty + r); ctx.stroke();
    ctx.lineWidth = 2; ctx.strokeStyle = paletteColour(t.id); ctx.stroke();
  }
}

function drawTrails() {
  for (const [id, t] of trails) {
    if (t.length < 2) continue;
    ctx.beginPath();
    t.forEach(([x, y], i) => { const [px, py] = toCanvas(x, y); if (i) ctx.lineTo(px, py); else ctx.moveTo(px, py); });
    ctx.lineWidth = 2; ctx.strokeStyle = paletteColour(id); ctx.globalAlpha = 0.55; ctx.stroke(); ctx.globalAlpha = 1;
  }
}

function drawRobots() {
  const radius = Math.max(7, Math.min(16, 0.5 * view.scale));
  for (const a of (state.agents || [])) {
    const [px, py] = toCanvas(a.x, a.y);
    ctx.beginPath(); ctx.arc(px, py, radius, 0, 2 * Math.PI);
    ctx.fillStyle = ROLE_COLOURS[a.role] || '#fff'; ctx.fill();
    ctx.lineWidth = 4; ctx.strokeStyle = '#000'; ctx.stroke();
    ctx.lineWidth = 3; ctx.strokeStyle = paletteColour(a.id); ctx.stroke();
    ctx.font = '700 11px system-ui, sans-serif';
    ctx.fillStyle = '#111'; ctx.textAlign = 'center'; ctx.textBaseline = 'middle';
    ctx.fillText(String(a.id), px, py + 0.5);
    ctx.textAlign = 'start'; ctx.textBaseline = 'alphabetic';
  }
}

function drawScaleBar(w, h) {
  const target = 120 / view.scale;  // metres in about 120 px
  const unit = Math.pow(10, Math.floor(Math.log10(target)));
  const metres = [1, 2, 5, 10].map((k) => k * unit).filter((v) => v <= target).pop() || unit;
  const px = metres * view.scale;
  const x = 20, y = h - 34;
  ctx.fillStyle = 'rgba(0,0,0,0.55)'; ctx.fillRect(x - 8, y - 18, px + 16, 30);
  ctx.fillStyle = '#fff'; ctx.fillRect(x, y, px, 4);
  label(metres + ' m', x, y - 5);
}

canvas.addEventListener('mousemove', (ev) => {
  if (!view) return;
  const r = canvas.getBoundingClientRect();
  const x = view.x0 + (ev.clientX - r.left - view.ox) / view.scale;
  const y = view.y1 - (ev.clientY - r.top - view.oy) / view.scale;
  $('hover').textContent = 'x ' + x.toFixed(2) + ' m, y ' + y.toFixed(2) + ' m';
});
// Wheel: zoom about the pointer; drag: pan; double click: back to the action.
canvas.addEventListener('wheel', (ev) => {
  if (!view) return;
  ev.preventDefault();
  const r = canvas.getBoundingClientRect();
  const x = view.x0 + (ev.clientX - r.left - view.ox) / view.scale;
  const y = view.y1 - (ev.clientY - r.top - view.oy) / view.scale;
  const k = Math.exp(ev.deltaY * 0.0015);
  const b = worldBox();
  custom = { x0: x + (b.x0 - x) * k, y0: y + (b.y0 - y) * k, x1: x + (b.x1 - x) * k, y1: y + (b.y1 - y) * k };
  setFraming('custom');
}, { passive: false });
let dragging = null;
canvas.addEventListener('mousedown', (ev) => { dragging = [ev.clientX, ev.clientY]; });
window.addEventListener('mouseup', () => { dragging = null; });
window.addEventListener('mousemove', (ev) => {
  if (!dragging || !view) return;
  const dx = (ev.clientX - dragging[0]) / view.scale, dy = (ev.clientY - dragging[1]) / view.scale;
  dragging = [ev.clientX, ev.clientY];
  const b = worldBox();
  custom = { x0: b.x0 - dx, y0: b.y0 + dy, x1: b.x1 - dx, y1: b.y1 + dy };
  setFraming('custom');
});
canvas.addEventListener('dblclick', () => setFraming('action'));
for (const b of document.querySelectorAll('#framing button')) b.addEventListener('click', () => setFraming(b.dataset.framing));
window.addEventListener('resize', draw);
poll();
