// The bench's deadline figures with and without the page (docs/hil.md, "The
// monitoring page"): `vines hil SCENE --realtime --duration S` without
// --serve, with --serve and no client, with a client reading the event
// stream without drawing it, and with the page open in headless chromium
// (puppeteer-core) for the whole run; ROUNDS rounds, interleaved.
// Prints one JSON line per run, with the machine's load average (1 min)
// before it; tools/page_deadlines.sh turns them into a stamped table
// (docs/figures/page_deadlines.md).
//
//   NODE_PATH=build/release/browser_test/node_modules node tests/browser/deadlines.js VINES SCENE S [ROUNDS]
"use strict";

const { spawn } = require("child_process");
const http = require("http");
const os = require("os");
const puppeteer = require("puppeteer-core");

const [vines, scene, seconds, rounds = "1"] = process.argv.slice(2);
const chromium = process.env.VINES_CHROMIUM || "/usr/bin/chromium";

// One run; with a page: the browser opens it as soon as it is served.
async function run(kind, browser) {
  const args = ["hil", scene, "--realtime", "--duration", seconds, "--json"];
  if (kind !== "no page") args.push("--serve", "0");
  const load = os.loadavg()[0];
  const p = spawn(vines, args);
  let out = "", err = "", opened = null, streamed = null;
  p.stdout.on("data", (d) => (out += d));
  p.stderr.on("data", (d) => {
    err += d;
    const m = /the page is at (http:\/\/\S+)/.exec(err);
    if (m && kind === "page open" && !opened)
      opened = browser.newPage().then(async (page) => { await page.goto(m[1]); return page; });
    if (m && kind === "stream read, no browser" && !streamed) streamed = readStream(m[1] + "events");
  });
  const code = await new Promise((res) => p.on("exit", res));
  // What the open page got (every kept sample: it kept up).
  let page_samples = null;
  if (opened) {
    const page = await opened;
    await page.waitForFunction(() => window.vinesPage.ended, { timeout: 10000 });
    page_samples = await page.evaluate(() => window.vinesPage.k.length);
    await page.close();
  }
  if (streamed) page_samples = await streamed;
  if (code !== 0) throw new Error(`vines hil exit ${code}: ${err}`);
  const r = JSON.parse(out);
  return { kind, load, steps: r.steps, deadline_misses: r.deadline_misses, latency_us: r.latency_us, page_samples };
}

// A client of the event stream that reads it to its end without drawing
// (the server's own cost, apart from a browser's): the kept samples it got.
function readStream(url) {
  return new Promise((res, rej) => {
    http.get(url, (r) => {
      let text = "";
      r.setEncoding("utf8");
      r.on("data", (d) => (text += d));
      r.on("end", () => {
        let n = 0;
        for (const m of text.matchAll(/^event: frame\ndata: (.*)$/gm)) n += JSON.parse(m[1]).k.length;
        res(n);
      });
    }).on("error", rej);
  });
}

async function main() {
  const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox"] });
  try {
    for (let i = 0; i < Number(rounds); ++i)
      for (const kind of ["no page", "served, no client", "stream read, no browser", "page open"])
        console.log(JSON.stringify({ round: i + 1, ...(await run(kind, browser)) }));
  } finally {
    await browser.close();
  }
}

main().catch((e) => {
  console.error(e.stack || String(e));
  process.exitCode = 1;
});
