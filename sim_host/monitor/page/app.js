// The monitoring page: the run's events (/events, Server-Sent Events) into
// uPlot charts. What it received is kept in window.vinesPage (the browser
// test reads it back): meta, k (the samples kept), data[name] (one array per
// series), derived[label] (the lines computed from them), alarms (the alarm
// history), report, ended; and what the twin's "now" panels drew at their
// last redraw: evidence (each story's statistic against the threshold) and
// factors (each story's stiffness factor and its sd), with their bars'
// geometry in CSS pixels of their canvas.
"use strict";

const page = { meta: null, k: [], t: [], data: {}, derived: {}, alarms: [], report: null, ended: false,
               evidence: null, factors: null };
window.vinesPage = page;

// The charts, one per panel, in this order; each its title. The twin's
// decision first: each story's statistic now against the threshold
// (evidence), each story's factor now (stiffness), the largest statistic
// over time (largest, computed from the statistics).
const PANELS = [
  ["evidence", "Evidence now: each story's statistic against the threshold"],
  ["stiffness", "Story stiffness factors now (whisker: 2 sd)"],
  ["largest", "Largest statistic over time"],
  ["ground", "Ground acceleration"], ["floors", "Floors"], ["device", "Device"],
  ["contact", "Contacts"],
  ["health", "Device health (band: 2 sd)"], ["residual", "Twin residual"], ["alarm", "Story in alarm"],
  ["force", "Load cell"], ["tracking", "Table tracking (vRTHS)"],
];
// The named story, the second one, the others (bars).
const NAMED = "#c9302c", SECOND = "#f0ad4e", OTHER = "#4a7ab0", THRESHOLD = "#000000";
const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                "#bcbd22", "#17becf", "#000000"];
// Node flags (firmware/include/vines/link/messages.hpp).
const FLAG_RESIDUAL = 1 << 5, FLAG_DAMAGE = 1 << 8, FLAG_DEVICE = 1 << 9;

const charts = [];  // {plot, lines, banded} or {draw} (the bar charts)
let dirty = false;

function el(tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text) e.textContent = text;
  return e;
}

// One chart: the panel's lines against time, each {label, stroke, dash,
// get} (get: its values, one a kept sample); stiffness and health with a
// band of eta +- 2 sd (two hidden series filled between).
function makePanel(panel, title) {
  const box = el("div", "panel");
  box.dataset.panel = panel;
  box.appendChild(el("h2", null, title));
  document.getElementById("charts").appendChild(box);
  return box;
}

// The width a chart has in its panel: the panel's, less its padding.
function innerWidth(box) {
  const cs = getComputedStyle(box);
  return Math.max(100, Math.floor(box.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight)));
}

const HEIGHT = 200;
function makeChart(panel, title, unit, lines, banded, yScale, ySplits) {
  const box = makePanel(panel, title);
  const opts = {
    width: innerWidth(box), height: HEIGHT, legend: { live: true },
    scales: { x: { time: false } },
    axes: [{ label: "t [s]" }, { label: unit, size: 60, splits: ySplits }],
    series: [{ label: "t" }], bands: [],
  };
  // The story in alarm on a scale of the stories (0: none), not auto-ranged
  // around a line of zeros.
  if (panel === "alarm")
    opts.scales.y = { range: (u, min, max) => [0, Math.max(page.meta.stories || 0, max || 0, 1)] };
  if (yScale) opts.scales.y = yScale;
  lines.forEach((l, i) => opts.series.push({ label: l.label, stroke: l.stroke || COLORS[i % COLORS.length],
                                             width: 1, dash: l.dash }));
  if (banded) {
    lines.forEach((l, i) => {
      const hi = opts.series.length;
      opts.series.push({ label: l.label + " +2sd", stroke: "transparent", show: true });
      opts.series.push({ label: l.label + " -2sd", stroke: "transparent", show: true });
      opts.bands.push({ series: [hi, hi + 1], fill: COLORS[i % COLORS.length] + "22" });
    });
  }
  const plot = new uPlot(opts, [[]], box);
  // The bands' bounds stay out of the legend.
  box.querySelectorAll(".u-legend .u-series").forEach((row, i) => { if (i > lines.length) row.style.display = "none"; });
  // The chart fills its panel's width, as the window changes.
  new ResizeObserver(() => {
    const w = innerWidth(box);
    if (w !== plot.width) plot.setSize({ width: w, height: HEIGHT });
  }).observe(box);
  charts.push({ plot, lines, banded });
}

// Lines computed from the series grow with the data (each value computed
// once), kept in page.derived[label].
function derived(label, at, style) {
  const cache = (page.derived[label] = []);
  return Object.assign({ label, get() { for (let i = cache.length; i < page.t.length; ++i) cache.push(at(i)); return cache; } },
                       style);
}

// A series of the run as a chart's line.
const seriesLine = (s) => ({ label: s.label, name: s.name, get: () => page.data[s.name] });

// The device's panel: the sphere (or the TMD's mass) relative to the floor
// it sits on, and the VI NES box's walls at +- the free travel, when the
// page has that floor; otherwise the series as the run gives them.
function deviceLines(series) {
  const dev = page.meta.device || {}, floor = dev.floor_series;
  const mass = series.find((s) => s.name === "particle_x_m");
  if (!mass || !floor || !page.data[floor]) return series.map(seriesLine);
  const what = dev.kind === "tmd" ? "TMD mass" : "sphere";
  const floorLabel = page.meta.series.find((s) => s.name === floor).label;
  const x = page.data.particle_x_m, f = page.data[floor];
  const lines = [derived(`${what} relative to the ${floorLabel}`, (i) => x[i] - f[i])];
  if (dev.gap_m > 0)
    for (const sign of [-1, 1])
      lines.push(derived(sign < 0 ? "left wall" : "right wall", () => sign * dev.gap_m, { stroke: "#555", dash: [6, 4] }));
  return lines;
}

// ---- The twin's "now" panels: a bar per story, on a canvas as wide as its
// panel, redrawn with the newest sample (and when the panel's width changes).
const BAR_HEIGHT = 220, PAD = { left: 48, right: 12, top: 14, bottom: 30 };

// A canvas filling its panel; draw(ctx, w, h) paints it in CSS pixels.
function makeBarChart(panel, title, draw) {
  const box = makePanel(panel, title);
  const canvas = el("canvas", "bars");
  const note = el("div", "note");
  box.appendChild(canvas);
  box.appendChild(note);
  const chart = {
    canvas, note,
    draw() {
      const w = innerWidth(box), dpr = window.devicePixelRatio || 1;
      if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(BAR_HEIGHT * dpr)) {
        canvas.width = Math.round(w * dpr);
        canvas.height = Math.round(BAR_HEIGHT * dpr);
        canvas.style.width = w + "px";
        canvas.style.height = BAR_HEIGHT + "px";
      }
      const ctx = canvas.getContext("2d");
      ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
      ctx.clearRect(0, 0, w, BAR_HEIGHT);
      ctx.font = "11px system-ui, sans-serif";
      draw(ctx, w, BAR_HEIGHT, note);
    },
  };
  new ResizeObserver(() => chart.draw()).observe(box);
  charts.push(chart);
  return chart;
}

// The stories' slots along x: story j (1-based) centred in its slot.
function slots(n, w) {
  const left = PAD.left, width = w - PAD.left - PAD.right, slot = width / n;
  return { slot, bar: Math.max(2, Math.round(slot * 0.6)), centre: (j) => left + slot * (j - 0.5) };
}

// The bar's colour: the named story, the second one, the others.
const barFill = (story, named, second) => (story === named ? NAMED : story === second ? SECOND : OTHER);

// The story axis and a y axis of ticks [value, label] mapped by y().
function axes(ctx, w, h, n, ticks, y) {
  ctx.strokeStyle = "#ccc";
  ctx.fillStyle = "#444";
  ctx.lineWidth = 1;
  ctx.textAlign = "right";
  ctx.textBaseline = "middle";
  for (const [v, label] of ticks) {
    const yy = Math.round(y(v)) + 0.5;
    ctx.beginPath();
    ctx.moveTo(PAD.left, yy);
    ctx.lineTo(w - PAD.right, yy);
    ctx.stroke();
    ctx.fillText(label, PAD.left - 6, yy);
  }
  const sl = slots(n, w);
  ctx.textAlign = "center";
  ctx.textBaseline = "top";
  for (let j = 1; j <= n; ++j) ctx.fillText(String(j), sl.centre(j), h - PAD.bottom + 4);
  ctx.fillText("story", PAD.left - 24, h - PAD.bottom + 4);
}

// The value each story's series has at the newest sample.
const now = (name) => { const a = page.data[name]; return a && a.length ? a[a.length - 1] : undefined; };
const fmt = (v) => (v >= 100 ? v.toFixed(0) : v >= 10 ? v.toFixed(1) : v.toPrecision(2));

// The statistics on an asinh scale (linear below 1, logarithmic above: 0.5,
// 12 and 1000 all read), y(v) = bottom - asinh(v) / asinh(top) (bottom - top).
function evidencePanel(n) {
  return makeBarChart("evidence", PANELS[0][1] + " (asinh scale)", (ctx, w, h, note) => {
    const i = page.t.length - 1;
    if (i < 0) return;
    const stat = [];
    for (let j = 1; j <= n; ++j) stat.push(now(`stat_${j}`));
    const threshold = now("stat_threshold"), named = now("alarm_story") || 0, second = now("second_story") || 0;
    const detected = ((now("flags") || 0) & FLAG_DAMAGE) !== 0;
    const biggest = Math.max(threshold, ...stat.map((v) => Math.max(0, v)));
    const top = Math.pow(10, Math.max(2, Math.ceil(Math.log10(Math.max(1, biggest * 1.2)))));
    const plot = { left: PAD.left, right: w - PAD.right, top: PAD.top, bottom: h - PAD.bottom };
    const y = (v) => plot.bottom - (Math.asinh(Math.max(0, v)) / Math.asinh(top)) * (plot.bottom - plot.top);
    const ticks = [[0, "0"]];
    for (let v = 1; v <= top; v *= 10) ticks.push([v, v >= 1e4 ? v.toExponential(0) : String(v)]);
    axes(ctx, w, h, n, ticks, y);
    const sl = slots(n, w), bars = [];
    stat.forEach((v, j) => {
      const story = j + 1, x = Math.round(sl.centre(story) - sl.bar / 2), yt = y(v);
      const fill = barFill(story, named, second);
      ctx.fillStyle = fill;
      ctx.fillRect(x, yt, sl.bar, plot.bottom - yt);
      ctx.fillStyle = "#222";
      ctx.textAlign = "center";
      ctx.textBaseline = "bottom";
      ctx.fillText(fmt(v), sl.centre(story), yt - 2);
      bars.push({ story, value: v, x, y: yt, w: sl.bar, h: plot.bottom - yt, fill });
    });
    // The threshold: a line across the plot, on top of the bars.
    const ty = Math.round(y(threshold));
    ctx.fillStyle = THRESHOLD;
    ctx.fillRect(plot.left, ty - 1, plot.right - plot.left, 2);
    ctx.textAlign = "left";
    ctx.textBaseline = "bottom";
    ctx.fillText(`threshold ${fmt(threshold)}`, plot.left + 4, ty - 3);
    page.evidence = { k: page.k[i], t: page.t[i], stat, threshold, named, second, detected, top, plot, bars,
                      thresholdY: ty };
    const over = stat.filter((v) => v > threshold).length;
    note.textContent = `t = ${page.t[i].toFixed(2)} s: largest ${fmt(Math.max(...stat))} (story ` +
      `${stat.indexOf(Math.max(...stat)) + 1}), ${over} of ${n} stories over the threshold; ` +
      (named ? `story ${named} named` + (second ? `, story ${second} second` : "") :
       detected ? "damage, story not identified" : "no story named") +
      (page.data.damage_size ? "" : " (the CSV has no sizes or onset)");
  });
}

// A CSV of an earlier version: the factors, but no statistics.
function noEvidencePanel() {
  const box = makePanel("evidence", PANELS[0][1]);
  box.appendChild(el("div", "note", "no statistics: this run's CSV is of an earlier version (no stat_ columns); " +
    "the factors and the story in alarm below are the run's"));
  page.evidence = { none: true };
}

// Each story's factor now: a bar from 1 (the drawing) to the factor, a
// whisker of +- 2 sd, the named story highlighted.
function factorsPanel(n) {
  return makeBarChart("stiffness", PANELS[1][1], (ctx, w, h, note) => {
    const i = page.t.length - 1;
    if (i < 0) return;
    const eta = [], sd = [];
    for (let j = 1; j <= n; ++j) eta.push(now(`eta_${j}`)), sd.push(now(`eta_sd_${j}`) || 0);
    const named = now("alarm_story") || 0, second = now("second_story") || 0;
    let lo = Math.min(0.9, ...eta.map((v, j) => v - 2 * sd[j])), hi = Math.max(1.05, ...eta.map((v, j) => v + 2 * sd[j]));
    lo = Math.floor(lo * 20 - 0.2) / 20, hi = Math.ceil(hi * 20 + 0.2) / 20;
    const plot = { left: PAD.left, right: w - PAD.right, top: PAD.top, bottom: h - PAD.bottom };
    const y = (v) => plot.bottom - ((v - lo) / (hi - lo)) * (plot.bottom - plot.top);
    const step = hi - lo > 0.6 ? 0.2 : hi - lo > 0.3 ? 0.1 : 0.05, ticks = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9; v += step) ticks.push([v, v.toFixed(2)]);
    axes(ctx, w, h, n, ticks, y);
    const sl = slots(n, w), bars = [];
    eta.forEach((v, j) => {
      const story = j + 1, c = sl.centre(story), x = Math.round(c - sl.bar / 2), fill = barFill(story, named, second);
      const y1 = y(1), yv = y(v);
      ctx.fillStyle = fill;
      ctx.fillRect(x, Math.min(y1, yv), sl.bar, Math.max(1, Math.abs(yv - y1)));
      ctx.strokeStyle = "#222";
      ctx.lineWidth = 1;
      const ya = y(v + 2 * sd[j]), yb = y(v - 2 * sd[j]), cap = sl.bar / 4;
      ctx.beginPath();
      ctx.moveTo(c, ya), ctx.lineTo(c, yb);
      ctx.moveTo(c - cap, ya), ctx.lineTo(c + cap, ya);
      ctx.moveTo(c - cap, yb), ctx.lineTo(c + cap, yb);
      ctx.stroke();
      ctx.fillStyle = "#222";
      ctx.textAlign = "center";
      ctx.textBaseline = "top";
      ctx.fillText(v.toFixed(3), c, Math.min(plot.bottom - 12, Math.max(y1, yv, yb) + 2));
      bars.push({ story, eta: v, sd: sd[j], x, y: Math.min(y1, yv), w: sl.bar, h: Math.abs(yv - y1), fill });
    });
    // The drawing's stiffness (factor 1).
    ctx.strokeStyle = "#555";
    ctx.setLineDash([6, 4]);
    ctx.beginPath();
    ctx.moveTo(plot.left, Math.round(y(1)) + 0.5);
    ctx.lineTo(plot.right, Math.round(y(1)) + 0.5);
    ctx.stroke();
    ctx.setLineDash([]);
    page.factors = { k: page.k[i], t: page.t[i], eta, sd, named, second, lo, hi, plot, bars };
    note.textContent = `t = ${page.t[i].toFixed(2)} s; 1: the drawing's stiffness; bar: the factor, whisker: +- 2 sd`;
  });
}

function onMeta(m) {
  page.meta = m;
  for (const s of m.series) page.data[s.name] = [];
  document.getElementById("source").textContent =
    `${m.live ? "live" : "replay of"} ${m.source}, ${m.mode}, ${m.rate_hz} Hz (every ${m.every}th sample)`;
  const has = (name) => m.series.some((s) => s.name === name);
  // The twin's stories (their factors eta_1 ...): the "now" panels.
  let n = 0;
  while (has(`eta_${n + 1}`)) ++n;
  const stats = n > 0 && has("stat_threshold") && has(`stat_${n}`);
  for (const [panel, title] of PANELS) {
    if (panel === "evidence") {
      if (n > 0) stats ? evidencePanel(n) : noEvidencePanel();
      continue;
    }
    if (panel === "stiffness") {
      if (n > 0) factorsPanel(n);
      continue;
    }
    if (panel === "largest") {
      // The largest of the stories' statistics at each sample, against the
      // threshold, on the evidence's asinh scale.
      if (!stats) continue;
      const st = [];
      for (let j = 1; j <= n; ++j) st.push(page.data[`stat_${j}`]);
      const lines = [derived("largest statistic", (i) => Math.max(...st.map((a) => a[i]))),
                     derived("threshold", (i) => page.data.stat_threshold[i], { stroke: THRESHOLD, dash: [6, 4] })];
      const decades = (u) => {
        const ticks = [0];
        for (let v = 1; v <= u.scales.y.max; v *= 10) ticks.push(v);
        return ticks;
      };
      makeChart(panel, title + " (asinh scale)", "statistic", lines, false,
                { distr: 4, asinh: 1, range: (u, min, max) => [0, Math.max(100, max * 1.5)] }, decades);
      continue;
    }
    const series = m.series.filter((s) => s.panel === panel);
    if (!series.length) continue;
    const lines = panel === "device" ? deviceLines(series) : series.map(seriesLine);
    makeChart(panel, title, series[0].unit, lines, panel === "health");
  }
}

// The alarm banner and its history, from the newest sample: the stories
// named; the banner adds the decision's sizes and onset (verdict), which
// move with each update and stay out of the history.
let lastAlarm = "";
function alarmText(i, verdict) {
  const d = page.data, parts = [];
  const story = d.alarm_story ? d.alarm_story[i] : 0, second = d.second_story ? d.second_story[i] : 0;
  const flags = d.flags ? d.flags[i] : 0;
  const v = verdict ? verdictText(i) : "", more = v ? ` (${v})` : "";
  if (story > 0 && second > 0) parts.push(`damage: stories ${story} and ${second}${more}`);
  else if (story > 0) parts.push(`damage: story ${story}${more}`);
  else if (flags & FLAG_DAMAGE) parts.push(`damage, story not identified${more}`);
  if (flags & FLAG_DEVICE) parts.push("device: TMD detuned");
  if ((flags & FLAG_RESIDUAL) && page.meta.mode === "twin") parts.push("residual over its limit");
  return parts.join(", ");
}

// The decision's sizes and onset at the newest sample, for the banner.
function verdictText(i) {
  const d = page.data;
  if (!d.damage_size || !d.flags || !(d.flags[i] & FLAG_DAMAGE)) return "";
  const pct = (v) => `${(100 * v).toFixed(1)} %`;
  const parts = [d.second_story[i] > 0 ? `losses ${pct(d.damage_size[i])} and ${pct(d.second_size[i])}`
                                        : `loss ${pct(d.damage_size[i])}`];
  if (d.onset_s[i] >= 0) parts.push(`onset ${d.onset_s[i].toFixed(2)} s`);
  return parts.join(", ");
}

function onFrame(f) {
  const rate = page.meta.rate_hz;
  page.meta.series.forEach((s, j) => { for (const v of f.v[j]) page.data[s.name].push(v === null ? NaN : v); });
  for (let i = 0; i < f.k.length; ++i) {
    page.k.push(f.k[i]);
    page.t.push(f.k[i] / rate);
    const n = page.k.length - 1, a = alarmText(n);
    if (a !== lastAlarm) {
      page.alarms.push({ t: page.t[n], k: page.k[n], alarm: a });
      lastAlarm = a;
    }
  }
  dirty = true;
}

// At most four redraws a second: each draws every chart whole, and the
// browser often shares the machine with the bench.
const REDRAW_MS = 250;
let lastDraw = 0;
function redraw(now) {
  if (dirty && (now - lastDraw >= REDRAW_MS || page.ended)) {
    dirty = false;
    lastDraw = now;
    for (const c of charts) {
      if (c.draw) {
        c.draw();
        continue;
      }
      const cols = [page.t].concat(c.lines.map((l) => l.get()));
      if (c.banded) {
        for (const l of c.lines) {
          const eta = page.data[l.name], sd = page.data[l.name.replace("eta_", "eta_sd_")] || [];
          cols.push(eta.map((v, i) => v + 2 * (sd[i] || 0)), eta.map((v, i) => v - 2 * (sd[i] || 0)));
        }
      }
      c.plot.setData(cols);
    }
    const banner = document.getElementById("alarm");
    // Red for damage or a detuned device, amber for the residual alone (a
    // model or noise warning, not a finding about the building).
    banner.textContent = (lastAlarm && alarmText(page.t.length - 1, true)) || "no alarm";
    banner.className = /damage|device/.test(lastAlarm) ? "on" : lastAlarm ? "warn" : "";
    document.getElementById("history").textContent = page.alarms
      .map((a) => `t = ${a.t.toFixed(2)} s: ${a.alarm || "cleared"}`).join("\n") || "none";
    document.getElementById("status").textContent =
      `${page.ended ? "run ended" : "running"}, t = ${(page.t[page.t.length - 1] || 0).toFixed(2)} s`;
  }
  requestAnimationFrame(redraw);
}

// The report's headline figures (the whole report stays in window.vinesPage).
function onReport(r) {
  page.report = r;
  const lines = [`steps ${r.steps} of ${r.samples}, deadline misses ${r.deadline_misses}`];
  if (r.latency_us) lines.push(`latency mean ${r.latency_us.mean.toFixed(1)} us, p99 ${r.latency_us.p99.toFixed(1)} us`);
  if (r.twin) {
    const tw = r.twin;
    const pct = (v) => `${(100 * v).toFixed(1)} %`;
    const where = tw.stories && tw.stories.length > 1
      ? `stories ${tw.stories.join(" and ")}, ${tw.sizes.map(pct).join(" and ")}`
      : tw.story ? `story ${tw.story}, ${pct(tw.size)}` : `story not identified, ${pct(tw.size)}`;
    lines.push(tw.detected ? `damage: ${where}, detected at ${tw.detect_time_s.toFixed(2)} s` +
                             (tw.onset_s !== null && tw.onset_s !== undefined ? `, onset ${tw.onset_s.toFixed(2)} s` : "")
                           : "no damage detected");
    if (tw.device)
      lines.push("device: " + Object.entries(tw.device)
        .map(([k, v]) => `${k.replace(/_/g, " ")} ${typeof v === "number" ? +v.toPrecision(4) : v}`).join(", "));
  }
  if (r.hybrid) {
    const h = r.hybrid, f = (v) => (v === null || v === undefined ? "-" : v.toFixed(3));
    lines.push(`tracking delay ${f(h.tracking_delay_ms)} ms, RMS ${f(h.tracking_rms_pct)} %, peak ${f(h.tracking_peak_pct)} %`);
    lines.push(`x_r hybrid ${f(h.x_r_hybrid)} / pure ${f(h.x_r_pure)}`);
  }
  document.getElementById("report").textContent = lines.join("\n");
}

const es = new EventSource("/events");
es.addEventListener("meta", (e) => onMeta(JSON.parse(e.data)));
es.addEventListener("frame", (e) => onFrame(JSON.parse(e.data)));
es.addEventListener("report", (e) => onReport(JSON.parse(e.data)));
es.addEventListener("end", () => { page.ended = true; dirty = true; es.close(); });
es.onerror = () => { if (!page.ended) document.getElementById("status").textContent = "disconnected"; };
requestAnimationFrame(redraw);
