// The bench's deadline figures with and without the page (docs/hil.md, "The
// monitoring page"): `vines hil SCENE --realtime --duration S` without
// --serve, with --serve and no client, and with the page open in headless
// chromium (puppeteer-core) for the whole run; ROUNDS rounds, interleaved.
// Prints one JSON line per run and a table.
//
//   NODE_PATH=build/release/browser_test/node_modules node tests/browser/deadlines.js VINES SCENE S [ROUNDS]
"use strict";

const { spawn } = require("child_process");
const puppeteer = require("puppeteer-core");

const [vines, scene, seconds, rounds = "1"] = process.argv.slice(2);
const chromium = process.env.VINES_CHROMIUM || "/usr/bin/chromium";

// One run; with a page: the browser opens it as soon as it is served.
async function run(kind, browser) {
  const args = ["hil", scene, "--realtime", "--duration", seconds, "--json"];
  if (kind !== "no page") args.push("--serve", "0");
  const p = spawn(vines, args);
  let out = "", err = "", opened = null;
  p.stdout.on("data", (d) => (out += d));
  p.stderr.on("data", (d) => {
    err += d;
    const m = /the page is at (http:\/\/\S+)/.exec(err);
    if (m && kind === "page open" && !opened)
      opened = browser.newPage().then(async (page) => { await page.goto(m[1]); return page; });
  });
  const code = await new Promise((res) => p.on("exit", res));
  if (opened) await (await opened).close();
  if (code !== 0) throw new Error(`vines hil exit ${code}: ${err}`);
  const r = JSON.parse(out);
  return { kind, steps: r.steps, deadline_misses: r.deadline_misses, latency_us: r.latency_us };
}

async function main() {
  const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox"] });
  const rows = [];
  try {
    for (let i = 0; i < Number(rounds); ++i)
      for (const kind of ["no page", "served, no client", "page open"]) {
        const r = await run(kind, browser);
        console.log(JSON.stringify(r));
        rows.push(r);
      }
  } finally {
    await browser.close();
  }
  console.log("| run | steps | deadline misses | latency mean / p99 / max (us) |\n|---|---|---|---|");
  for (const r of rows) {
    const l = r.latency_us;
    console.log(`| ${r.kind} | ${r.steps} | ${r.deadline_misses} | ${l.mean.toFixed(0)} / ${l.p99.toFixed(0)} / ${l.max.toFixed(0)} |`);
  }
}

main().catch((e) => {
  console.error(e.stack || String(e));
  process.exitCode = 1;
});
