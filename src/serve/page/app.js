// pfx preview: plays the frames the server renders, shows the diagnostics
// of the file as `pfx validate` prints them, the emitters' tracks, pick and
// A/B. It uses only the routes man pfx(1) lists: /api/state, /frame/K.png,
// /events, /pick and /api/compare. Frames are kept per version: the current
// one, and the one before it (A in A/B, and what plays while a new version
// renders); A may instead be another file or seed (the server's comparison,
// ?variant=compare), whose frames are kept for its version alone.
'use strict';

const token = new URLSearchParams(location.search).get('token') || '';
const q = (path) => path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token);
const $ = (id) => document.getElementById(id);

let state = null;            // the last /api/state
const caches = new Map();    // version -> Map(frame -> {bmp, opaque})
let previous = 0;            // the version before the current one
let pinned = 0;              // a version kept as A (0: A is the one before)
let compare = null;          // the comparison's /api/state?variant=compare, or null
let compareFrames = new Map(); // frame -> {bmp, opaque} of compare.version
let compareAsked = -1;       // the comparison's frame being fetched
const inflight = new Set();  // "version:frame" being fetched
let time = 0;                // the playhead, seconds from frame 0
let playing = true, speed = 1, fit = true;
let loopIn = 0, loopOut = -1; // frames; loopOut < 0: the last
let wipe = 0.5;
let lastDrawn = null;        // {version, frame}
let pendingDraw = false;
window.pfxShown = null;      // {version, frame, at}: when a version's first frame was shown

const frames = () => (state && state.frames) || 0;
const fps = () => (state && state.fps) || 30;
const lastFrame = () => (loopOut >= 0 ? loopOut : frames() - 1);
const frameAt = (t) => Math.max(0, Math.min(frames() - 1, Math.floor(t * fps() + 1e-6)));
const cacheOf = (v) => { if (!caches.has(v)) caches.set(v, new Map()); return caches.get(v); };
const escapeHtml = (s) => s.replace(/[&<>]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;' })[c]);

// ---- the server's state

async function refreshState() {
  const r = await fetch(q('/api/state'));
  if (!r.ok) return;
  const s = await r.json();
  const old = state;
  state = s;
  if (!old || old.version !== s.version) {
    if (old && old.version) previous = old.version;
    for (const [v, held] of [...caches])
      if (v !== s.version && v !== previous && v !== pinned) {
        // Decoded frames are a megabyte each at 512x512: let them go now.
        for (const e of held.values()) { e.bmp.close(); if (e.opaque) e.opaque.close(); }
        caches.delete(v);
      }
    buildTracks(); // emitters may have come, gone or moved

  }
  if (time * fps() >= frames()) time = 0;
  if (s.compare && !old) showCompareChoice(s.compare);
  if (!s.compare !== !compare || (s.compare && compare && s.compare.file !== compare.file)) await refreshCompare();
  showState();
  drawGraphs();
  requestDraw();
}

function showState() {
  $('file').textContent = state.file;
  const bad = state.diagnostics.some((d) => d.severity === 'error');
  const v = $('version');
  v.textContent = state.version ? 'version ' + state.version : 'no good version';
  v.className = 'badge ' + (bad ? 'bad' : 'good');
  $('stale').hidden = !bad || !state.version;
  const diag = $('diag');
  const text = state.diagnostics_text || '';
  diag.className = 'diag' + (text ? '' : ' empty');
  diag.innerHTML = text ? text.split('\n').map((l) => {
    const m = / (error|warning): /.exec(l);
    return m ? '<span class="' + m[1] + '">' + escapeHtml(l) + '</span>' : escapeHtml(l);
  }).join('\n') : 'No problems.';
  if (state.render_error) diag.textContent += '\n' + state.render_error;
  const done = (state.stats || []).filter((x) => x).length;
  $('status').textContent = !state.version ? 'waiting for a file that compiles'
    : done < frames() ? 'rendered ' + done + ' of ' + frames() + ' frames'
    : 'all ' + frames() + ' frames rendered';
  const count = $('diag-count');
  count.textContent = state.diagnostics.length;
  count.className = 'count' + (bad ? ' bad' : '');
  buildRuler();
}

// ---- frames

async function fetchFrame(k, ahead) {
  const key = state.version + ':' + k;
  if (inflight.has(key) || !state.version) return;
  inflight.add(key);
  try {
    const r = await fetch(q('/frame/' + k + '.png' + (ahead ? '?ahead=1' : '')));
    if (!r.ok) return;
    const v = Number(r.headers.get('X-Pfx-Version'));
    const bmp = await createImageBitmap(await r.blob(), { premultiplyAlpha: 'none' });
    const entry = { bmp, opaque: null };
    if (state.alpha === 'premultiplied') entry.opaque = await opaqueOf(bmp);
    cacheOf(v).set(k, entry);
    if (v > state.version) await refreshState();
    requestDraw();
  } finally {
    inflight.delete(key);
  }
}

// A premultiplied PNG's colour with alpha 1: drawn additively over the
// background scaled by 1 - alpha, it composites as premultiplied colour must.
async function opaqueOf(bmp) {
  const c = new OffscreenCanvas(bmp.width, bmp.height);
  const g = c.getContext('2d');
  g.drawImage(bmp, 0, 0);
  const img = g.getImageData(0, 0, bmp.width, bmp.height);
  for (let i = 3; i < img.data.length; i += 4) img.data[i] = 255;
  g.putImageData(img, 0, 0);
  return createImageBitmap(c);
}

// The frame to show for k: the current version's; until the new version
// has its first frame, the one before (so a save never blanks the view,
// and playback never mixes two versions once the new one is there).
function frameFor(k) {
  const cur = state && caches.get(state.version);
  if (cur && cur.has(k)) return { entry: cur.get(k), version: state.version };
  const old = caches.get(previous);
  if ((!cur || cur.size === 0) && old && old.has(k)) return { entry: old.get(k), version: previous };
  return null;
}

// Asks for the playhead's frame alone until it is here (after a save the
// server renders it before anything else), then a few ahead as
// look-aheads (?ahead=1), which never take the server's playhead from it.
function pump() {
  if (!state || !state.version) return;
  const k = frameAt(time), cur = cacheOf(state.version);
  if (!cur.has(k)) { fetchFrame(k, false); return; }
  if ($('ab').value !== 'off' && comparing() && k < compare.frames && !compareFrames.has(k))
    fetchCompareFrame(k);
  for (let i = 1, asked = 0; i <= 8 && inflight.size < 2 && asked < 1; i++) {
    const f = k + i > lastFrame() ? loopIn + (k + i - lastFrame() - 1) : k + i;
    if (f < frames() && !cur.has(f)) { fetchFrame(f, true); asked++; }
  }
}

// ---- A against another file or seed: the server's second session

// The page's controls set to what the server compares (--compare FILE
// chooses a file, side by side, at start).
function showCompareChoice(c) {
  $('against').value = c.seed === null ? 'file' : 'seed';
  $('against-file').value = c.seed === null ? c.file : '';
  $('against-seed').value = c.seed === null ? '' : c.seed;
  $('against-file').hidden = c.seed !== null;
  $('against-seed').hidden = c.seed === null;
  if ($('ab').value === 'off') $('ab').value = 'side';
}

function dropCompareFrames() {
  for (const e of compareFrames.values()) { e.bmp.close(); if (e.opaque) e.opaque.close(); }
  compareFrames = new Map();
}

// Re-reads the comparison's state; its frames go when its version changes.
async function refreshCompare() {
  const r = state && state.compare ? await fetch(q('/api/state?variant=compare')) : null;
  const c = r && r.ok ? await r.json() : null;
  if (!c || !compare || c.version !== compare.version || c.file !== compare.file) dropCompareFrames();
  compare = c;
  requestDraw();
}

// Asks the server to compare with a file or a seed (or nothing).
async function setCompare() {
  const how = $('against').value, file = $('against-file').value.trim();
  const seed = $('against-seed').value.trim();
  const arg = how === 'file' && file ? '?file=' + encodeURIComponent(file)
    : how === 'seed' && seed !== '' ? '?seed=' + encodeURIComponent(seed) : '';
  const r = await fetch(q('/api/compare' + arg), { method: 'POST' });
  $('against-error').textContent = r.ok ? '' : await r.text();
  await refreshState();
  await refreshCompare();
}

const comparing = () => $('against').value !== 'version' && compare && compare.version;

async function fetchCompareFrame(k) {
  if (compareAsked >= 0) return;
  compareAsked = k;
  const v = compare.version;
  try {
    const r = await fetch(q('/frame/' + k + '.png?variant=compare'));
    if (!r.ok) return;
    const bmp = await createImageBitmap(await r.blob(), { premultiplyAlpha: 'none' });
    const entry = { bmp, opaque: compare.alpha === 'premultiplied' ? await opaqueOf(bmp) : null };
    if (compare && Number(r.headers.get('X-Pfx-Version')) === compare.version && v === compare.version)
      compareFrames.set(k, entry);
    requestDraw();
  } finally {
    compareAsked = -1;
  }
}

// ---- drawing

const view = $('view');
const g = view.getContext('2d');
let checker = null;

function paintBackground(x, w, h) {
  const mode = $('bg').value;
  if (mode === 'checker') {
    if (!checker) {
      const c = new OffscreenCanvas(16, 16), cg = c.getContext('2d');
      cg.fillStyle = '#666'; cg.fillRect(0, 0, 16, 16);
      cg.fillStyle = '#999'; cg.fillRect(0, 0, 8, 8); cg.fillRect(8, 8, 8, 8);
      checker = g.createPattern(c, 'repeat');
    }
    g.fillStyle = checker;
  } else {
    g.fillStyle = mode === 'colour' ? $('bg-colour').value : mode;
  }
  g.fillRect(x, 0, w, h);
}

// One frame at x over the background: straight alpha as the browser
// composites; premultiplied as C + (1 - a) bg.
function paintFrame(entry, x) {
  if (!entry.opaque) { g.drawImage(entry.bmp, x, 0); return; }
  g.globalCompositeOperation = 'destination-out';
  g.drawImage(entry.bmp, x, 0);
  g.globalCompositeOperation = 'lighter';
  g.drawImage(entry.opaque, x, 0);
  g.globalCompositeOperation = 'source-over';
}

function draw() {
  pendingDraw = false;
  if (!state || !state.size) return;
  const [w, h] = state.size, k = frameAt(time), mode = $('ab').value;
  const b = frameFor(k), av = pinned || previous;
  const a = comparing() ? compareFrames.get(k) : caches.get(av) && caches.get(av).get(k);
  const width = mode === 'side' ? 2 * w : w;
  if (view.width !== width || view.height !== h) { view.width = width; view.height = h; }
  fitView();
  $('wipe-handle').hidden = mode !== 'wipe';
  if (mode === 'side') {
    paintBackground(0, w, h); if (a) paintFrame(a, 0);
    paintBackground(w, w, h); if (b) paintFrame(b.entry, w);
  } else if (mode === 'diff') {
    g.fillStyle = '#000'; g.fillRect(0, 0, w, h);
    if (a) g.drawImage(a.bmp, 0, 0);
    g.globalCompositeOperation = 'difference';
    if (b) g.drawImage(b.entry.bmp, 0, 0);
    g.globalCompositeOperation = 'source-over';
  } else {
    paintBackground(0, w, h);
    if (mode === 'wipe') {
      if (a) paintFrame(a, 0);
      g.save(); g.beginPath(); g.rect(wipe * w, 0, w, h); g.clip();
      paintBackground(0, w, h); if (b) paintFrame(b.entry, 0);
      g.restore();
      $('wipe-handle').style.left = (wipe * view.getBoundingClientRect().width) + 'px';
    } else if (b) {
      paintFrame(b.entry, 0);
    }
  }
  if (b) {
    lastDrawn = { version: b.version, frame: k };
    if (b.version === state.version && (!window.pfxShown || window.pfxShown.version !== b.version))
      window.pfxShown = { version: b.version, frame: k, at: Date.now() };
  }
  showClock(k);
}

// fit: the canvas as large as the stage holds, up or down, keeping its
// aspect (1:1: its own size). Set through the CSSOM, which the page's CSP
// allows (style attributes in markup it does not).
function fitView() {
  const wrap = $('stage-wrap'), pad = 16;
  if (!fit) { view.style.width = view.style.height = ''; return; }
  const s = Math.min((wrap.clientWidth - pad) / view.width, (wrap.clientHeight - pad) / view.height);
  if (s > 0) {
    view.style.width = Math.floor(view.width * s) + 'px';
    view.style.height = Math.floor(view.height * s) + 'px';
  }
}

function requestDraw() {
  if (!pendingDraw) { pendingDraw = true; requestAnimationFrame(draw); }
}

function showClock(k) {
  $('clock').textContent = k + ' / ' + (frames() - 1) + ' \u00b7 ' + (k / fps()).toFixed(3) + ' s';
  const x = (k + 0.5) / Math.max(1, frames());
  const lane = laneBox();
  $('playhead').style.left = (lane.left + x * lane.width) + 'px';
  const lr = $('loop-range');
  lr.style.left = (lane.left + loopIn / frames() * lane.width) + 'px';
  lr.style.width = ((lastFrame() + 1 - loopIn) / frames() * lane.width) + 'px';
  lr.hidden = loopIn === 0 && loopOut < 0;
  showStats(k);
}

function showStats(k) {
  const s = state.stats && state.stats[k];
  const rows = [['frame', k], ['time', (k / fps()).toFixed(3) + ' s']];
  if (s) {
    rows.push(['sprites drawn', s.sprites], ['simulate + render', s.ms.toFixed(1) + ' ms']);
    state.emitters.forEach((e, i) => rows.push(['alive: ' + e.name, s.alive[i]]));
  } else {
    rows.push(['', 'rendering\u2026']);
  }
  $('stats').innerHTML = rows.map(([a, b]) => '<tr><td>' + escapeHtml(String(a)) +
    '</td><td>' + escapeHtml(String(b)) + '</td></tr>').join('');
  document.querySelectorAll('.track .alive').forEach((el, i) => {
    el.textContent = s ? s.alive[i] : '';
  });
}

// ---- the timeline

function laneBox() {
  const t = $('timeline').getBoundingClientRect(), r = $('ruler').getBoundingClientRect();
  return { left: r.left - t.left, width: r.width };
}

// Elements are made with the DOM, not markup: the page's CSP allows no
// inline style attributes.
function el(tag, cls, text, left, width) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text !== undefined) e.textContent = text;
  if (left !== undefined) e.style.left = left + '%';
  if (width !== undefined) e.style.width = width + '%';
  return e;
}

function buildRuler() {
  const dur = frames() / fps(), ruler = $('ruler');
  const step = dur > 20 ? 5 : dur > 8 ? 1 : dur > 3 ? 0.5 : dur > 1.5 ? 0.25 : 0.1;
  ruler.replaceChildren();
  for (let i = 0; i * step < dur - 1e-9; i++)
    ruler.appendChild(el('span', '', +(i * step).toFixed(2) + ' s', i * step / dur * 100));
}

function buildTracks() {
  const dur = frames() / fps(), tracks = $('tracks');
  tracks.replaceChildren();
  for (const e of state.emitters || []) {
    const row = el('div', 'track'), name = el('div', 'name', e.name + ' ');
    row.title = e.name + ': line ' + e.line + '; runs ' + e.start.toFixed(2) + ' to ' +
      e.end.toFixed(2) + ' s' + (e.bursts.length ? '; bursts at ' +
      e.bursts.map((t) => t.toFixed(2)).join(', ') + ' s' : '');
    const swatch = el('span', 'swatch');
    swatch.style.background = hue(state.emitters.indexOf(e), 1);
    name.prepend(swatch);
    name.appendChild(el('small', '', ':' + e.line));
    const lane = el('div', 'lane');
    lane.appendChild(el('div', 'run', undefined, e.start / dur * 100,
      Math.max(0, e.end - e.start) / dur * 100));
    const graph = el('canvas', 'graph');
    graph.width = 600; graph.height = 22;
    lane.appendChild(graph);
    for (const t of e.bursts) lane.appendChild(el('div', 'tick', undefined, t / dur * 100));
    for (const sp of e.spawns || [])
      row.title += '; ' + sp.event.replace('_', ' ') + ' \u2192 ' + sp.emitter;
    if (e.spawns && e.spawns.length)
      name.appendChild(el('small', 'spawns', ' \u2192 ' + e.spawns.map((sp) => sp.emitter).join(', ')));
    lane.appendChild(el('div', 'events'));
    lane.appendChild(el('span', 'alive'));
    row.append(name, lane);
    tracks.appendChild(row);
  }
}

// The frames where an emitter's particles raised sub-emitter events (into
// the emitters its spawns name), as runs of frames on its lane, from the
// per-frame event counts of the frames rendered so far.
function drawEvents() {
  const lanes = document.querySelectorAll('.track .events'), n = frames();
  const index = new Map((state.emitters || []).map((e, i) => [e.name, i]));
  (state.emitters || []).forEach((e, i) => {
    const box = lanes[i];
    if (!box) return;
    const targets = (e.spawns || []).map((sp) => index.get(sp.emitter));
    const fired = (f) => {
      const s = state.stats[f];
      return s && s.events ? targets.reduce((sum, t) => sum + s.events[t], 0) : 0;
    };
    box.replaceChildren();
    for (let f = 0; f < n; f++) {
      if (!fired(f)) continue;
      let last = f, count = 0;
      while (last + 1 < n && fired(last + 1)) last++;
      for (let g = f; g <= last; g++) count += fired(g);
      const mark = el('div', 'event', undefined, f / n * 100, (last + 1 - f) / n * 100);
      mark.dataset.first = f;
      mark.dataset.last = last;
      mark.title = count + ' sub-emitter event' + (count === 1 ? '' : 's') + ' (' +
        e.spawns.map((sp) => sp.event.replace('_', ' ') + ' \u2192 ' + sp.emitter).join(', ') +
        '), frame' + (last > f ? 's ' + f + '\u2013' + last : ' ' + f);
      box.appendChild(mark);
      f = last;
    }
  });
}

// An emitter's colour on the tracks: hues far apart, in emitter order.
const hue = (i, a) => 'hsla(' + ((200 + i * 137.5) % 360) + ', 65%, 62%, ' + a + ')';

// Live particles over time in each lane, from the frames rendered so far:
// when an emitter (and what its sub-emitters feed) is busy.
function drawGraphs() {
  const graphs = document.querySelectorAll('.track .graph');
  if (!state || !state.stats) return;
  drawEvents();
  graphs.forEach((c, i) => {
    const g2 = c.getContext('2d'), n = state.stats.length;
    let peak = 1;
    for (const s of state.stats) if (s) peak = Math.max(peak, s.alive[i]);
    g2.clearRect(0, 0, c.width, c.height);
    g2.fillStyle = hue(i, 0.55);
    state.stats.forEach((s, f) => {
      if (!s) return;
      const h = s.alive[i] / peak * c.height;
      g2.fillRect(f / n * c.width, c.height - h, Math.max(1, c.width / n), h);
    });
  });
}

function seekFromPointer(ev) {
  const lane = laneBox(), t = $('timeline').getBoundingClientRect();
  const x = (ev.clientX - t.left - lane.left) / lane.width;
  seek(Math.max(0, Math.min(frames() - 1, Math.floor(x * frames()))));
}

function seek(k) {
  time = k / fps();
  pump();
  requestDraw();
}

// ---- pick

async function pick(ev) {
  if (!state || !state.size) return;
  const r = view.getBoundingClientRect(), [w, h] = state.size;
  let x = Math.floor((ev.clientX - r.left) * view.width / r.width);
  const y = Math.floor((ev.clientY - r.top) * view.height / r.height);
  if ($('ab').value === 'wipe') { wipe = x / w; requestDraw(); return; }
  // Side by side, the left half is A: the comparison's own emitters and
  // lines when another file or seed is compared.
  const onA = $('ab').value === 'side' && x < w && comparing() && compare;
  x %= w;
  const k = frameAt(time);
  const res = await fetch(q('/pick?frame=' + k + '&x=' + x + '&y=' + y +
    (onA ? '&variant=compare' : '')));
  const list = res.ok ? await res.json() : [];
  const file = onA ? compare.file : state.file;
  $('pick').innerHTML = (list.length ? list.map((p) => '<li>' + escapeHtml(p.emitter) +
    '<span class="line">' + escapeHtml(file) + ':' + p.line + '</span></li>').join('')
    : '<li class="hint">No emitter drew pixel (' + x + ', ' + y + ').</li>') +
    '<li class="hint">frame ' + k + ', pixel (' + x + ', ' + y + ')</li>';
}

// ---- controls

function setPlaying(p) { playing = p; $('play').innerHTML = p ? '&#10074;&#10074;' : '&#9654;'; }
function step(d) {
  setPlaying(false);
  const k = frameAt(time) + d, n = frames();
  seek(((k % n) + n) % n);
}

$('play').onclick = () => setPlaying(!playing);
$('prev').onclick = () => step(-1);
$('next').onclick = () => step(1);
$('speed').onchange = (e) => { speed = Number(e.target.value); };
$('loop-in').onclick = () => { loopIn = frameAt(time); if (loopOut >= 0 && loopOut < loopIn) loopOut = -1; requestDraw(); };
$('loop-out').onclick = () => { loopOut = Math.max(loopIn, frameAt(time)); requestDraw(); };
$('loop-clear').onclick = () => { loopIn = 0; loopOut = -1; requestDraw(); };
$('bg').onchange = (e) => { $('bg-colour').hidden = e.target.value !== 'colour'; requestDraw(); };
$('bg-colour').oninput = requestDraw;
$('ab').onchange = requestDraw;
$('against').onchange = () => {
  const how = $('against').value;
  $('against-file').hidden = how !== 'file';
  $('against-seed').hidden = how !== 'seed';
  $('pin').hidden = how !== 'version';
  if ($('ab').value === 'off') $('ab').value = 'side';
  setCompare();
};
$('against-file').onchange = setCompare;
$('against-seed').onchange = setCompare;
// Pin: the current version stays A, however many saves follow (its frames
// are those the page fetched while it was current).
$('pin').onclick = () => {
  pinned = pinned ? 0 : state.version;
  $('pin').textContent = pinned ? 'A = v' + pinned + ' \u2715' : 'pin A';
  $('pin').title = pinned ? 'A is version ' + pinned + '; click to compare with the last version again'
    : 'keep the current version as A';
  requestDraw();
};
$('fit').onclick = () => {
  fit = !fit;
  $('stage').classList.toggle('fit', fit);
  $('fit').textContent = fit ? 'fit' : '1:1';
  requestDraw();
};
view.addEventListener('click', pick);
view.addEventListener('mousemove', (ev) => {
  if ($('ab').value !== 'wipe' || !(ev.buttons & 1)) return;
  const r = view.getBoundingClientRect();
  wipe = (ev.clientX - r.left) / r.width;
  requestDraw();
});
$('timeline').addEventListener('pointerdown', (ev) => {
  setPlaying(false);
  seekFromPointer(ev);
  const move = (e) => seekFromPointer(e);
  window.addEventListener('pointermove', move);
  window.addEventListener('pointerup', () => window.removeEventListener('pointermove', move), { once: true });
});
window.addEventListener('keydown', (ev) => {
  if (ev.target.tagName === 'SELECT' || ev.target.tagName === 'INPUT') return;
  if (ev.key === ' ') { setPlaying(!playing); ev.preventDefault(); }
  else if (ev.key === 'ArrowLeft') step(-1);
  else if (ev.key === 'ArrowRight') step(1);
  else if (ev.key === 'i') $('loop-in').click();
  else if (ev.key === 'o') $('loop-out').click();
});
window.addEventListener('resize', requestDraw);

// ---- the clock: advance while the next frame is there; wait for it if not

let before = performance.now();
function tick(now) {
  const dt = (now - before) / 1000;
  before = now;
  if (state && state.version) {
    const k = frameAt(time);
    if (playing && frameFor(k)) {
      let t = time + dt * speed;
      const end = (lastFrame() + 1) / fps();
      if (t >= end) t = loopIn / fps();
      if (frameFor(frameAt(t)) || frameAt(t) === k) time = t;
    }
    pump();
    const shown = lastDrawn && lastDrawn.frame === frameAt(time) &&
      lastDrawn.version === (frameFor(frameAt(time)) || {}).version;
    if (!shown) requestDraw();
  }
  requestAnimationFrame(tick);
}

// ---- live reload: a news event re-reads the state, keeping the playhead

const events = new EventSource(q('/events'));
events.addEventListener('news', () => refreshState());
events.addEventListener('open', () => refreshState());
setInterval(() => { if (state && state.stats && state.stats.includes(null)) refreshState(); }, 1000);
// The compared file is watched by the server too; its news are read here.
setInterval(() => { if (state && state.compare) refreshCompare(); }, 500);
$('stage').classList.toggle('fit', fit);
setPlaying(true);
refreshState().then(() => requestAnimationFrame(tick));

// For tests and scripts: the page's state, read-only.
window.pfx = {
  get state() { return state; },
  get frame() { return frameAt(time); },
  get shown() { return lastDrawn; },
  get compare() { return compare; },
  get compareFrames() { return compareFrames; },
  seek: (k) => { setPlaying(false); seek(k); },
  pause: () => setPlaying(false),
};
