// The monitoring page: the run's events (/events, Server-Sent Events) into
// uPlot charts. What it received is kept in window.vinesPage (the browser
// test reads it back): meta, k (the samples kept), data[name] (one array per
// series), derived[label] (the lines computed from them), alarms (the alarm
// history), report, ended.
"use strict";

const page = { meta: null, k: [], t: [], data: {}, derived: {}, alarms: [], report: null, ended: false };
window.vinesPage = page;

// The charts, one per panel, in this order; each its title.
const PANELS = [
  ["ground", "Ground acceleration"], ["floors", "Floors"], ["device", "Device"],
  ["contact", "Contacts"], ["stiffness", "Story stiffness factors (band: 2 sd)"],
  ["health", "Device health"], ["residual", "Twin residual"], ["alarm", "Story in alarm"],
  ["force", "Load cell"], ["tracking", "Table tracking (vRTHS)"],
];
const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                "#bcbd22", "#17becf", "#000000"];
// Node flags (firmware/include/vines/link/messages.hpp).
const FLAG_RESIDUAL = 1 << 5, FLAG_DAMAGE = 1 << 8, FLAG_DEVICE = 1 << 9;

const charts = [];  // {plot, lines, banded}
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
function makeChart(panel, title, unit, lines, banded) {
  const box = el("div", "panel");
  box.appendChild(el("h2", null, title));
  document.getElementById("charts").appendChild(box);
  const opts = {
    width: 540, height: 200, legend: { live: true },
    scales: { x: { time: false } },
    axes: [{ label: "t [s]" }, { label: unit, size: 60 }],
    series: [{ label: "t" }], bands: [],
  };
  // The story in alarm on a scale of the stories (0: none), not auto-ranged
  // around a line of zeros.
  if (panel === "alarm")
    opts.scales.y = { range: (u, min, max) => [0, Math.max(page.meta.stories || 0, max || 0, 1)] };
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
  charts.push({ plot, lines, banded });
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
  // Derived lines grow with the data (each value computed once).
  const derived = (label, at, style) => {
    const cache = (page.derived[label] = []);
    return Object.assign({ label, get() { for (let i = cache.length; i < page.t.length; ++i) cache.push(at(i)); return cache; } },
                         style);
  };
  const x = page.data.particle_x_m, f = page.data[floor];
  const lines = [derived(`${what} relative to the ${floorLabel}`, (i) => x[i] - f[i])];
  if (dev.gap_m > 0)
    for (const sign of [-1, 1])
      lines.push(derived(sign < 0 ? "left wall" : "right wall", () => sign * dev.gap_m, { stroke: "#555", dash: [6, 4] }));
  return lines;
}

function onMeta(m) {
  page.meta = m;
  for (const s of m.series) page.data[s.name] = [];
  document.getElementById("source").textContent =
    `${m.live ? "live" : "replay of"} ${m.source}, ${m.mode}, ${m.rate_hz} Hz (every ${m.every}th sample)`;
  for (const [panel, title] of PANELS) {
    const series = m.series.filter((s) => s.panel === panel);
    if (!series.length) continue;
    const lines = panel === "device" ? deviceLines(series) : series.map(seriesLine);
    makeChart(panel, title, series[0].unit, lines, panel === "stiffness" || panel === "health");
  }
}

// The alarm banner and its history, from the newest sample.
let lastAlarm = "";
function alarmText(i) {
  const d = page.data, parts = [];
  const story = d.alarm_story ? d.alarm_story[i] : 0;
  const flags = d.flags ? d.flags[i] : 0;
  if (story > 0) parts.push(`damage: story ${story}`);
  else if (flags & FLAG_DAMAGE) parts.push("damage");
  if (flags & FLAG_DEVICE) parts.push("device: TMD detuned");
  if ((flags & FLAG_RESIDUAL) && page.meta.mode === "twin") parts.push("residual over its limit");
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
    banner.textContent = lastAlarm || "no alarm";
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
    lines.push(tw.detected ? `damage: story ${tw.story}, ${(100 * tw.size).toFixed(1)} %, at ${tw.detect_time_s.toFixed(2)} s`
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
