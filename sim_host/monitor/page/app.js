// The monitoring page: the run's events (/events, Server-Sent Events) into
// uPlot charts. What it received is kept in window.vinesPage (the browser
// test reads it back): meta, k (the samples kept), data[name] (one array per
// series), alarms (the alarm history), report, ended.
"use strict";

const page = { meta: null, k: [], t: [], data: {}, alarms: [], report: null, ended: false };
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

const charts = [];  // {plot, names, bands}
let dirty = false;

function el(tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text) e.textContent = text;
  return e;
}

// One chart: the panel's series against time; stiffness and health with a
// band of eta +- 2 sd (two hidden series filled between).
function makeChart(panel, title, series) {
  const box = el("div", "panel");
  box.appendChild(el("h2", null, title));
  document.getElementById("charts").appendChild(box);
  const banded = panel === "stiffness" || panel === "health";
  const opts = {
    width: 540, height: 200, legend: { live: true },
    scales: { x: { time: false } },
    axes: [{ label: "t [s]" }, { label: series[0].unit, size: 60 }],
    series: [{ label: "t" }], bands: [],
  };
  series.forEach((s, i) => opts.series.push({ label: s.label, stroke: COLORS[i % COLORS.length], width: 1 }));
  if (banded) {
    series.forEach((s, i) => {
      const hi = opts.series.length;
      opts.series.push({ label: s.label + " +2sd", stroke: "transparent", show: true });
      opts.series.push({ label: s.label + " -2sd", stroke: "transparent", show: true });
      opts.bands.push({ series: [hi, hi + 1], fill: COLORS[i % COLORS.length] + "22" });
    });
  }
  const plot = new uPlot(opts, [[]], box);
  // The bands' bounds stay out of the legend.
  box.querySelectorAll(".u-legend .u-series").forEach((row, i) => { if (i > series.length) row.style.display = "none"; });
  charts.push({ plot, names: series.map((s) => s.name), banded });
}

function onMeta(m) {
  page.meta = m;
  for (const s of m.series) page.data[s.name] = [];
  document.getElementById("source").textContent =
    `${m.live ? "live" : "replay of"} ${m.source}, ${m.mode}, ${m.rate_hz} Hz (every ${m.every}th sample)`;
  for (const [panel, title] of PANELS) {
    const series = m.series.filter((s) => s.panel === panel);
    if (series.length) makeChart(panel, title, series);
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

function redraw() {
  if (dirty) {
    dirty = false;
    for (const c of charts) {
      const cols = [page.t].concat(c.names.map((n) => page.data[n]));
      if (c.banded) {
        for (const n of c.names) {
          const eta = page.data[n], sd = page.data[n.replace("eta_", "eta_sd_")] || [];
          cols.push(eta.map((v, i) => v + 2 * (sd[i] || 0)), eta.map((v, i) => v - 2 * (sd[i] || 0)));
        }
      }
      c.plot.setData(cols);
    }
    const banner = document.getElementById("alarm");
    banner.textContent = lastAlarm || "no alarm";
    banner.className = lastAlarm ? "on" : "";
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
    if (tw.device) lines.push(`device: ${JSON.stringify(tw.device)}`);
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
