// The monitoring page in a real browser (sim_host/monitor/README.md): Debian's
// headless chromium, driven over the DevTools protocol by puppeteer-core,
// loads the page of `vines hil --serve` during a digital-twin run against a
// damaged truth (story 3 at 90 %), and then `vines view` of the run's --csv
// (and of the same CSV without its statistics, as an earlier version wrote it).
// Checks: the page was live (data before the run ended); the values it
// plotted are the run's (read back from the page, against the --csv, bit for
// bit where the CSV is exact); every kept sample is there; the alarm names
// story 3 when the report does, at the sample it came; the replay equals the
// live page; in hybrid mode the table's tracking RMS is the report's; in
// replay the device panel's box (the sphere against its walls); on an
// undamaged building, no alarm; the twin's evidence panel draws the CSV's
// last statistics against the threshold, the named story highlighted; every
// chart fills its panel's width (1280 x 900 and 1920 x 1080). Saves
// screenshots.
//
//   node page_test.js VINES SOURCE_DIR OUT_DIR
"use strict";

const { spawn } = require("child_process");
const fs = require("fs");
const path = require("path");
const puppeteer = require("puppeteer-core");

const [vines, source, out] = process.argv.slice(2);
const chromium = process.env.VINES_CHROMIUM || "/usr/bin/chromium";
fs.mkdirSync(out, { recursive: true });

function fail(msg) {
  console.error("FAIL: " + msg);
  process.exitCode = 1;
}
function check(ok, msg) {
  if (!ok) fail(msg);
  return ok;
}

// A vines command; resolves with its page's URL (from "... the page is at URL").
function start(args) {
  const p = spawn(vines, args, { cwd: source });
  p.stdoutText = "";
  p.stderrText = "";
  p.stdout.on("data", (d) => (p.stdoutText += d));
  p.exited = new Promise((res) => p.on("exit", (code, signal) => res({ code, signal })));
  p.url = new Promise((res, rej) => {
    p.stderr.on("data", (d) => {
      p.stderrText += d;
      const m = /the page is at (http:\/\/\S+)/.exec(p.stderrText);
      if (m) res(m[1]);
    });
    p.exited.then((e) => rej(new Error(`vines ${args[0]} exited (${e.code}) before serving: ${p.stderrText}`)));
  });
  return p;
}

// The --csv as columns by name.
function readCsv(file) {
  const lines = fs.readFileSync(file, "utf8").trim().split("\n");
  const names = lines[0].split(",");
  const cols = {};
  names.forEach((n) => (cols[n] = []));
  for (const line of lines.slice(1)) line.split(",").forEach((c, j) => cols[names[j]].push(Number(c)));
  return cols;
}

// What the page holds (window.vinesPage, sim_host/monitor/page/app.js).
const pageData = (page) =>
  page.evaluate(() => {
    const p = window.vinesPage;
    return { meta: p.meta, k: p.k, data: p.data, derived: p.derived, alarms: p.alarms, report: p.report, ended: p.ended,
             evidence: p.evidence, factors: p.factors,
             banner: document.getElementById("alarm").textContent,
             bannerClass: document.getElementById("alarm").className,
             legend: Array.from(document.querySelectorAll(".u-legend .u-series")).map((e) => e.textContent) };
  });

// The decision's series the telemetry gives and the twin's --csv does not
// write (sim_host/monitor/rows.hpp: kDecisionSeries): checked against the report.
const DECISION_ONLY = ["second_story", "damage_size", "second_size", "onset_s"];

// Each chart's canvas against its panel: the widest canvas's share of the
// panel's width (uPlot's or the bar charts').
const chartWidths = (page) =>
  page.evaluate(() => Array.from(document.querySelectorAll("#charts .panel")).map((p) => {
    const w = Math.max(0, ...Array.from(p.querySelectorAll("canvas")).map((c) => c.getBoundingClientRect().width));
    return { panel: p.dataset.panel, share: w / p.getBoundingClientRect().width, canvases: p.querySelectorAll("canvas").length };
  }));

// At a window size: every panel's chart at least 95 % of its panel's width
// (the evidence panel of a CSV without statistics has none); a screenshot.
async function fillsPanels(page, width, height, shot, what) {
  await page.setViewport({ width, height });
  await new Promise((r) => setTimeout(r, 600));  // the resize, a redraw
  const widths = chartWidths(page);
  const got = await widths;
  const narrow = got.filter((c) => c.canvases > 0 && c.share < 0.95);
  check(got.length > 0 && narrow.length === 0,
    `${what} at ${width}x${height}: charts narrower than 95 % of their panels: ${JSON.stringify(narrow)}`);
  await page.screenshot({ path: path.join(out, shot), fullPage: true });
  return Math.min(...got.filter((c) => c.canvases > 0).map((c) => c.share));
}

// The evidence panel against the CSV at the page's last sample: each bar the
// story's statistic (rel. 1e-8: the CSV's 9 digits), its top where the
// asinh scale puts it, the threshold line at the threshold, the named story
// (and only it) in the highlight colour, read back from the canvas's pixels.
async function evidenceMatches(page, live, cols, what) {
  const ev = live.evidence, n = live.meta.stories, k = live.k[live.k.length - 1];
  if (!check(ev && !ev.none && ev.stat.length === n, `${what}: no evidence panel (${JSON.stringify(ev)})`)) return;
  check(ev.k === k, `${what}: the evidence is of sample ${ev.k}, the page's last is ${k}`);
  let worst = 0;
  for (let j = 1; j <= n; ++j) {
    const want = cols[`stat_${j}`][k], got = ev.stat[j - 1];
    worst = Math.max(worst, Math.abs(got - want) / Math.max(1, Math.abs(want)));
  }
  check(worst <= 1e-8, `${what}: the bars off the CSV's statistics by ${worst}`);
  check(ev.threshold === cols.stat_threshold[k], `${what}: threshold ${ev.threshold}, CSV ${cols.stat_threshold[k]}`);
  const p = ev.plot, y = (v) => p.bottom - (Math.asinh(Math.max(0, v)) / Math.asinh(ev.top)) * (p.bottom - p.top);
  const off = Math.max(...ev.bars.map((b) => Math.abs(b.y - y(b.value)) + Math.abs(b.y + b.h - p.bottom)));
  check(off < 0.5, `${what}: a bar ${off} px off its value on the asinh scale`);
  check(Math.abs(ev.thresholdY - y(ev.threshold)) <= 0.5, `${what}: the threshold line at ${ev.thresholdY}, ${y(ev.threshold)} wanted`);
  check(ev.named === cols.alarm_story[k], `${what}: named ${ev.named}, CSV's alarm_story ${cols.alarm_story[k]}`);
  // The pixels: in each bar (clear of the threshold line and the labels), and
  // on the threshold line right of the last bar.
  const px = await page.evaluate((ev) => {
    const c = document.querySelector('[data-panel="evidence"] canvas'), dpr = c.width / c.getBoundingClientRect().width;
    const at = (x, y) => Array.from(c.getContext("2d").getImageData(Math.round(x * dpr), Math.round(y * dpr), 1, 1).data.slice(0, 3));
    const inBar = (b) => {
      let yy = b.y + b.h * 0.75;
      if (Math.abs(yy - ev.thresholdY) < 4) yy = b.y + b.h * 0.35;
      return b.h >= 8 ? at(b.x + b.w / 2, yy) : null;
    };
    return { bars: ev.bars.map(inBar), line: at(ev.plot.right - 2, ev.thresholdY) };
  }, ev);
  const hex = (rgb) => "#" + rgb.map((v) => v.toString(16).padStart(2, "0")).join("");
  const red = px.bars.map((c, j) => (c && hex(c) === "#c9302c" ? j + 1 : 0)).filter((j) => j);
  const drawn = ev.bars.filter((b) => b.h >= 8).map((b) => b.story);
  check(JSON.stringify(red) === JSON.stringify(ev.named && drawn.includes(ev.named) ? [ev.named] : []),
    `${what}: bars in the highlight colour ${JSON.stringify(red)}, named ${ev.named}`);
  check(hex(px.line) === "#000000", `${what}: the threshold line's pixel ${hex(px.line)}`);
  return { k, stat: ev.stat, threshold: ev.threshold, named: ev.named, highlighted: red };
}

async function main() {
  const csv = path.join(out, "twin.csv");
  const run = start(["hil", "data/scenes/elcentro_vines.toml", "--mode", "twin", "--truth",
    "data/scenes/twin/truth_story3_loss10.toml", "--sensors", "3,6,8,10", "--measure-noise-pct", "5",
    "--floors", "3,6", "--realtime", "--grace", "1000", "--duration", "28", "--serve", "0", "--csv", csv, "--json"]);
  const url = await run.url;
  const browser = await puppeteer.launch({ executablePath: chromium, headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--window-size=1920,1080"], defaultViewport: { width: 1280, height: 900 } });
  try {
    const page = await browser.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(url);
    // Live: samples on the page while the run goes on.
    await page.waitForFunction(() => window.vinesPage.k.length > 200, { timeout: 60000 });
    const during = await pageData(page);
    check(!during.ended, "the page got its data only after the run ended");
    await page.waitForFunction(() => window.vinesPage.ended, { timeout: 120000 });
    await new Promise((r) => setTimeout(r, 300));  // a last redraw
    const share = [await fillsPanels(page, 1920, 1080, "monitor_twin_1920.png", "live"),
                   await fillsPanels(page, 1280, 900, "monitor_twin.png", "live")];
    const live = await pageData(page);  // as drawn at 1280 x 900
    check(errors.length === 0, "page errors: " + errors.join("; "));
    const exit = await run.exited;
    check(exit.code === 0, `vines hil exit ${exit.code}: ${run.stderrText}`);
    const report = JSON.parse(run.stdoutText);
    const cols = readCsv(csv);

    // Every kept sample (every 5th at 1 kHz, telemetry received) and only those.
    const every = live.meta.every;
    check(every === 5, `every ${every}`);
    const kept = cols.k.filter((k, r) => k % every === 0 && cols.received[r] === 1);
    check(JSON.stringify(live.k) === JSON.stringify(kept), `kept samples: page ${live.k.length}, CSV ${kept.length}`);
    // The values: bit for bit where the CSV writes 17 digits, within its 9
    // digits for the twin's own columns.
    const exact = ["ag_sent_mps2", "x_top_m", "x_3_m", "x_6_m", "contact_force_n", "flags", "aux", "alarm_story"];
    let compared = 0;
    for (const s of live.meta.series) {
      if (DECISION_ONLY.includes(s.name)) continue;
      const tol = exact.includes(s.name) ? 0 : 1e-8;
      const got = live.data[s.name], want = cols[s.name];
      if (!check(want !== undefined, `series ${s.name} not in the CSV`)) continue;
      let worst = 0;
      live.k.forEach((k, i) => {
        const d = Math.abs(got[i] - want[k]);
        worst = Math.max(worst, tol === 0 ? d : d / Math.max(1, Math.abs(want[k])));
      });
      check(worst <= tol, `${s.name}: page against CSV off by ${worst} (allowed ${tol})`);
      compared += got.length;
    }
    check(live.meta.series.length === 47, `${live.meta.series.length} series (47: 10 stories and the device with sd, ` +
      "10 statistics and the threshold, the decision's 4, floors 3, 6)");
    const ev = await evidenceMatches(page, live, cols, "live");
    // The alarm: the report's story, on the banner, from the sample it came.
    const tw = report.twin;
    check(tw.detected && tw.story === 3, `report: detected ${tw.detected}, story ${tw.story}`);
    check(/damage: story 3/.test(live.banner) && live.bannerClass === "on", `banner "${live.banner}" (${live.bannerClass})`);
    const first = live.alarms.find((a) => /story 3/.test(a.alarm));
    if (check(first !== undefined, "no alarm in the page's history")) {
      const firstCsv = cols.k.find((k, r) => cols.alarm_story[r] === 3 && k % every === 0);
      check(first.k === firstCsv, `alarm on the page at k ${first.k}, in the CSV's kept samples at ${firstCsv}`);
      check(Math.abs(first.t - tw.detect_time_s) <= every / 1000, `alarm at ${first.t} s, report ${tw.detect_time_s} s`);
    }
    check(live.report && live.report.twin.story === 3 && live.report.steps === report.steps, "the page's report");
    // The decision's sizes and onset (not in the CSV) at the last sample: the report's, on the banner.
    const last = live.k.length - 1, pct = (v) => `${(100 * v).toFixed(1)} %`;
    check(live.k[last] === report.samples - 1, `the page's last sample ${live.k[last]}, of ${report.samples}`);
    check(live.data.damage_size[last] === tw.size && live.data.second_story[last] === 0 &&
          live.data.onset_s[last] === (tw.onset_s === null ? -1 : tw.onset_s),
      `the decision on the page: size ${live.data.damage_size[last]}, onset ${live.data.onset_s[last]}; report ${tw.size}, ${tw.onset_s}`);
    check(live.banner.includes(`loss ${pct(tw.size)}`) && (tw.onset_s === null || live.banner.includes(`onset ${tw.onset_s.toFixed(2)} s`)),
      `banner "${live.banner}": not the report's size ${pct(tw.size)} and onset ${tw.onset_s}`);
    console.log(`live: ${live.k.length} samples x ${live.meta.series.length} series (${compared} values) equal ` +
      `to the CSV; alarm story 3 at ${first && first.t} s (report ${tw.detect_time_s} s); ` +
      `deadline misses ${report.deadline_misses}, latency p99 ${report.latency_us.p99.toFixed(1)} us`);
    if (ev)
      console.log(`live evidence at k ${ev.k}: statistics [${ev.stat.map((v) => v.toPrecision(3)).join(", ")}] equal to the ` +
        `CSV's, threshold ${ev.threshold}, story ${ev.named} highlighted (${JSON.stringify(ev.highlighted)}); banner ` +
        `"${live.banner}"; charts at least ${(100 * Math.min(...share)).toFixed(1)} % of their panels' width`);

    // The replay of the run's --csv: the same page.
    const view = start(["view", csv, "--serve", "0"]);
    const page2 = await browser.newPage();
    await page2.goto(await view.url);
    await page2.waitForFunction(() => window.vinesPage.ended, { timeout: 60000 });
    const replay = await pageData(page2);
    check(JSON.stringify(replay.k) === JSON.stringify(live.k), "view: other samples than live");
    for (const s of live.meta.series) {
      if (DECISION_ONLY.includes(s.name)) continue;
      const a = live.data[s.name], b = replay.data[s.name] || [];
      const tol = exact.includes(s.name) ? 0 : 1e-8;
      const worst = a.reduce((w, v, i) => Math.max(w, Math.abs(v - b[i]) / Math.max(1, Math.abs(v))), 0);
      check(b.length === a.length && worst <= tol, `view: ${s.name} off the live page by ${worst}`);
    }
    check(/damage: story 3/.test(replay.banner), `view banner "${replay.banner}"`);
    await new Promise((r) => setTimeout(r, 300));  // a last redraw
    const replayNow = await pageData(page2);
    const rev = await evidenceMatches(page2, replayNow, cols, "view");
    // The same bars as live (the CSV's 9 digits against the telemetry's: within 0.01 px), the same colours.
    const rb = (replayNow.evidence && replayNow.evidence.bars) || [], lb = live.evidence.bars;
    check(rev && ev && rb.length === lb.length && rb.every((b, j) => b.fill === lb[j].fill && b.x === lb[j].x &&
          Math.abs(b.y - lb[j].y) < 0.01 && Math.abs(b.h - lb[j].h) < 0.01) &&
          replayNow.evidence.thresholdY === live.evidence.thresholdY,
      "view: the evidence panel drawn otherwise than live");
    check(replayNow.factors && replayNow.factors.eta.every((v, j) => Math.abs(v - live.factors.eta[j]) <= 1e-8),
      "view: other factors now than live");
    await fillsPanels(page2, 1280, 900, "monitor_view.png", "view");
    view.kill("SIGINT");
    const vexit = await view.exited;
    check(vexit.code === 0, `vines view exit ${vexit.code} ${vexit.signal} on Ctrl-C`);
    console.log(`view: ${replay.k.length} samples equal to the live page, the same evidence bars; screenshots in ${out}`);
    await olderCsv(browser, csv, replayNow);
    await hybrid(browser);
    await deviceBox(browser);
    await noFalseAlarm(browser);
  } finally {
    await browser.close();
    run.kill();
  }
}

// A twin CSV of an earlier version (no stat_ columns): `vines view` shows it,
// the evidence panel saying it has no statistics, the factors as the newer CSV's.
async function olderCsv(browser, csv, replay) {
  const lines = fs.readFileSync(csv, "utf8").trim().split("\n");
  const keep = lines[0].split(",").map((n, j) => (/^stat_/.test(n) ? -1 : j)).filter((j) => j >= 0);
  const old = path.join(out, "twin_no_stats.csv");
  fs.writeFileSync(old, lines.map((l) => { const c = l.split(","); return keep.map((j) => c[j]).join(","); }).join("\n") + "\n");
  const view = start(["view", old, "--serve", "0"]);
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(await view.url);
  await page.waitForFunction(() => window.vinesPage.ended, { timeout: 60000 });
  await new Promise((r) => setTimeout(r, 300));
  const got = await pageData(page);
  const text = await page.$eval('[data-panel="evidence"]', (e) => e.textContent).catch(() => "");
  check(errors.length === 0, "older CSV: page errors: " + errors.join("; "));
  check(got.evidence && got.evidence.none && /no statistics/.test(text), `older CSV: evidence panel "${text}"`);
  check(!got.meta.series.some((s) => /^stat_/.test(s.name)), "older CSV: statistics on the page");
  check(JSON.stringify(got.factors.eta) === JSON.stringify(replay.factors ? replay.factors.eta : null) &&
        /damage: story 3/.test(got.banner), `older CSV: factors or banner ("${got.banner}") not the newer CSV's`);
  await fillsPanels(page, 1280, 900, "monitor_view_no_stats.png", "older CSV");
  view.kill("SIGINT");
  await view.exited;
  console.log(`older CSV (no statistics): shown, the evidence panel says "${text.replace(/^.*?(no statistics[^;]*).*$/, "$1")}"`);
}

// Hybrid mode (the TMD on the table, 4 s in real time): the table, its
// command and the load cell as the CSV has them, bit for bit; the tracking
// RMS the page shows at the last sample equals the report's
// tracking_rms_pct (computed apart, by rths_criteria.cpp).
async function hybrid(browser) {
  const csv = path.join(out, "hybrid.csv");
  const run = start(["hil", "data/scenes/elcentro_tmd.toml", "--mode", "hybrid", "--realtime", "--grace", "100",
    "--duration", "4", "--serve", "0", "--csv", csv, "--json"]);
  const page = await browser.newPage();
  await page.goto(await run.url);
  await page.waitForFunction(() => window.vinesPage.ended, { timeout: 60000 });
  const live = await pageData(page);
  await page.screenshot({ path: path.join(out, "monitor_hybrid.png"), fullPage: true });
  const exit = await run.exited;
  check(exit.code === 0, `vines hil --mode hybrid exit ${exit.code}: ${run.stderrText}`);
  const report = JSON.parse(run.stdoutText), cols = readCsv(csv);
  for (const name of ["ag_sent_mps2", "x_top_m", "table_x_m", "aux", "force_measured_n"]) {
    const got = live.data[name] || [];
    const worst = live.k.reduce((w, k, i) => Math.max(w, Math.abs(got[i] - cols[name][k])), 0);
    check(got.length === live.k.length && worst === 0, `hybrid ${name}: page against CSV off by ${worst}`);
  }
  const last = live.k[live.k.length - 1], shown = live.data.tracking_rms_pct[live.k.length - 1];
  const want = report.hybrid.tracking_rms_pct;
  check(last === report.samples - 1, `hybrid: last sample on the page ${last}, of ${report.samples}`);
  check(Math.abs(shown - want) <= 1e-9 * want, `hybrid: tracking RMS on the page ${shown} %, report ${want} %`);
  check(/tracking delay/.test(await page.$eval("#report", (e) => e.textContent)), "hybrid: the vRTHS criteria shown");
  console.log(`hybrid: ${live.k.length} samples equal to the CSV; tracking RMS ${shown.toFixed(4)} % ` +
    `(report ${want.toFixed(4)} %)`);
}

// A bench run in lock step (as fast as the link allows: the run may end
// before the page opens, which then gets it from the history: --serve-hold),
// its page once ended, the --json report and the --csv's columns.
async function lockStep(browser, name, args) {
  const csv = path.join(out, `${name}.csv`);
  // --serve-hold: the run may end before the page opens; it is kept up
  // until the page has read it all.
  const run = start(["hil", ...args, "--serve", "0", "--serve-hold", "60", "--csv", csv, "--json"]);
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(await run.url);
  await page.waitForFunction(() => window.vinesPage.ended, { timeout: 60000 });
  await new Promise((r) => setTimeout(r, 300));  // a last redraw
  const live = await pageData(page);
  await page.screenshot({ path: path.join(out, `monitor_${name}.png`), fullPage: true });
  const exit = await run.exited;
  check(exit.code === 0, `${name}: vines hil exit ${exit.code}: ${run.stderrText}`);
  check(errors.length === 0, `${name}: page errors: ` + errors.join("; "));
  return { live, report: JSON.parse(run.stdoutText), cols: readCsv(csv) };
}

// Replay of the VI NES (20 s): every sample in contact is on the page; the
// device panel draws the sphere relative to its floor (the top one) and the
// box's walls at +- the free travel. The
// sphere is never farther out than the walls and a touch of their overlap,
// and wherever the contact force is on, it is at a wall: the walls drawn
// are where the run's contacts happen.
async function deviceBox(browser) {
  const { live, cols } = await lockStep(browser, "replay_vines",
    ["data/scenes/elcentro_vines.toml", "--duration", "20"]);
  const d = live.data, gap = live.meta.device.gap_m;
  // Every 5th sample and every sample in contact (an impact is a few ms:
  // the page draws each whole, its peak included), as the CSV has them.
  const kept = cols.k.filter((k, r) => k % 5 === 0 || cols.contact_force_n[r] !== 0);
  check(JSON.stringify(live.k) === JSON.stringify(kept), `replay: kept samples: page ${live.k.length}, CSV ${kept.length}`);
  check(live.k.every((k, i) => d.contact_force_n[i] === cols.contact_force_n[k] && d.particle_x_m[i] === cols.particle_x_m[k]),
    "replay: the device's values on the page are not the CSV's");
  const peak = (a) => a.reduce((m, v) => Math.max(m, Math.abs(v)), 0);
  check(peak(d.contact_force_n) === peak(cols.contact_force_n), "replay: the page misses the peak contact force");
  const inContact = cols.contact_force_n.filter((f) => f !== 0).length;
  // Its replay keeps the same samples, and draws the same sphere.
  const view = start(["view", path.join(out, "replay_vines.csv"), "--serve", "0"]);
  const vpage = await browser.newPage();
  await vpage.goto(await view.url);
  await vpage.waitForFunction(() => window.vinesPage.ended, { timeout: 60000 });
  const replay = await pageData(vpage);
  view.kill("SIGINT");
  await view.exited;
  check(JSON.stringify(replay.k) === JSON.stringify(live.k), "replay: vines view keeps other samples");
  const rel = live.derived["sphere relative to the top floor"] || [];
  check(live.meta.device.kind === "vines" && gap > 0, `replay: device ${JSON.stringify(live.meta.device)}`);
  check(rel.length === live.k.length && rel.every((r, i) => r === d.particle_x_m[i] - d.x_top_m[i]),
    "replay: the sphere relative to the top floor is not particle_x_m - x_top_m");
  const walls = [live.derived["left wall"] || [], live.derived["right wall"] || []];
  check(JSON.stringify(replay.derived["sphere relative to the top floor"]) === JSON.stringify(rel),
    "replay: vines view draws another sphere");
  check(walls[0].length === rel.length && walls[0].every((w) => w === -gap) && walls[1].every((w) => w === gap),
    "replay: the walls are not at +- the free travel");
  let contacts = 0, worst = 0, outside = 0;
  rel.forEach((r, i) => {
    outside = Math.max(outside, Math.abs(r) - gap);
    if (d.contact_force_n[i] !== 0) {
      ++contacts;
      worst = Math.max(worst, gap - Math.abs(r));
    }
  });
  check(contacts > 0 && contacts === inContact, `replay: ${contacts} samples in contact on the page, ${inContact} in the CSV`);
  check(worst <= 0, `replay: in contact ${worst} m inside the walls`);
  // Beyond a wall by the contact's overlap only (a few mm here: the Hertz
  // overlap of this 1.2 m sphere).
  check(outside > 0 && outside <= 1e-2 * gap, `replay: the sphere ${outside} m beyond a wall (gap ${gap} m)`);
  check(live.legend.some((t) => /left wall/.test(t)), "replay: the walls are not in the chart's legend");
  console.log(`replay: ${rel.length} samples, the sphere within +-${gap.toFixed(5)} m walls (at most ` +
    `${outside.toExponential(2)} m beyond, the contact's overlap); ${contacts} samples in contact ` +
    `(the CSV: ${inContact}), all at a wall; peak contact force ${peak(d.contact_force_n).toExponential(3)} N as in the CSV`);
}

// The twin on an undamaged building (the truth is the scene itself, the same
// sensors and noise as the damaged run above), the whole record: the report
// detects nothing, and the page shows no alarm at any sample.
async function noFalseAlarm(browser) {
  const { live, report, cols } = await lockStep(browser, "twin_undamaged",
    ["data/scenes/elcentro_vines.toml", "--mode", "twin", "--sensors", "3,6,8,10", "--measure-noise-pct", "5"]);
  check(!report.twin.detected, `undamaged: the report detects story ${report.twin.story}`);
  // The residual may be over its limit (the default 0.05 m/s^2 is below the
  // 5 % noise and the impacts' spikes): an amber warning, not an alarm.
  check(!/damage|device/.test(live.banner) && live.bannerClass !== "on",
    `undamaged: banner "${live.banner}" (${live.bannerClass})`);
  check(live.alarms.every((a) => !/damage|device/.test(a.alarm)), `undamaged: alarms ${JSON.stringify(live.alarms)}`);
  check(report.twin.residual_alarm_steps === 0 || live.bannerClass === "warn",
    `undamaged: the residual over its limit ${report.twin.residual_alarm_steps} steps, banner class "${live.bannerClass}"`);
  check(live.data.alarm_story.every((s) => s === 0) && cols.alarm_story.every((s) => s === 0),
    "undamaged: a story in alarm on the page or in the CSV");
  check(live.k.length === Math.ceil(report.samples / live.meta.every), `undamaged: ${live.k.length} samples on the page`);
  console.log(`undamaged twin: ${live.k.length} samples (${report.samples} steps), no damage or device alarm on the ` +
    `page or in the report; banner "${live.banner}" (residual over its limit ${report.twin.residual_alarm_steps} steps)`);
}

main().catch((e) => {
  fail(e.stack || String(e));
});
