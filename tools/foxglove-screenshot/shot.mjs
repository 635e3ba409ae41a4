// Opens an MCAP log in Foxglove Studio 1.48.0 (its web build from npm, @foxglove/studio-base)
// with a layout, in headless Chromium, seeks to k, and saves a screenshot. Fails (exit 1)
// when the viewer reports a problem with the log (a "Player problem": a channel it cannot
// read), and prints the problems.
//
//   node shot.mjs LOG.mcap OUT.png [--layout FILE] [--k 0.5] [--size 1600x900]
//                 [--wait SECONDS] [--chromium PATH]
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { McapIndexedReader } from "@mcap/core";
import puppeteer from "puppeteer-core";

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const opt = (name, dflt) => {
  const i = args.indexOf(name);
  return i >= 0 ? args.splice(i, 2)[1] : dflt;
};
const layout = opt("--layout", path.join(here, "../../docs/foxglove-layout.json"));
const k = Number(opt("--k", "0.5"));
const [width, height] = opt("--size", "1600x900").split("x").map(Number);
const wait = Number(opt("--wait", "20"));
const chromium = opt("--chromium", "/usr/bin/chromium");
const [log, out] = args;
if (!log || !out) {
  console.error("usage: node shot.mjs LOG.mcap OUT.png [--layout FILE] [--k K] [--size WxH] [--wait S] [--chromium PATH]");
  process.exit(2);
}

// The log's first message time: k maps to t0 + 10 k s.
const fd = await fs.promises.open(log, "r");
const size = (await fd.stat()).size;
const reader = await McapIndexedReader.Initialize({
  readable: {
    size: async () => BigInt(size),
    read: async (offset, length) => {
      const buf = new Uint8Array(Number(length));
      await fd.read(buf, 0, buf.length, Number(offset));
      return buf;
    },
  },
});
await fd.close();
const t0 = reader.statistics?.messageStartTime;
if (t0 === undefined) throw new Error(`${log}: no statistics (is the log finished?)`);
const tns = t0 + BigInt(Math.round(k * 10e9));
const seconds = tns / 1000000000n;
const nanos = String(tns % 1000000000n).padStart(9, "0");
const time = new Date(Number(seconds) * 1000).toISOString().replace(/\.\d+Z$/, `.${nanos}Z`);

// The page, Studio's bundle, React, the layout and the log, with byte ranges (Studio reads a
// remote MCAP file through its index).
const modules = path.join(here, "node_modules");
const files = {
  "/": path.join(here, "www/index.html"),
  "/main.js": path.join(here, "www/main.js"),
  "/react.production.min.js": path.join(modules, "react/umd/react.production.min.js"),
  "/react-dom.production.min.js": path.join(modules, "react-dom/umd/react-dom.production.min.js"),
  "/layout.json": layout,
  "/log.mcap": log,
};
const types = { ".html": "text/html", ".js": "text/javascript", ".json": "application/json", ".wasm": "application/wasm", ".png": "image/png", ".ttf": "font/ttf" };
const server = http.createServer((req, res) => {
  const u = decodeURIComponent(new URL(req.url, "http://x").pathname);
  const f = files[u] ?? (u.startsWith("/assets/") ? path.join(modules, "@foxglove/studio-base", path.normalize(u)) : undefined);
  fs.stat(f ?? "", (err, st) => {
    if (err || !st.isFile()) {
      res.writeHead(404);
      res.end();
      return;
    }
    const h = { "Content-Type": types[path.extname(f)] ?? "application/octet-stream", "Accept-Ranges": "bytes" };
    const m = /bytes=(\d+)-(\d*)/.exec(req.headers.range ?? "");
    const [a, b] = m ? [Number(m[1]), m[2] ? Math.min(Number(m[2]), st.size - 1) : st.size - 1] : [0, st.size - 1];
    res.writeHead(m ? 206 : 200, { ...h, "Content-Length": b - a + 1, ...(m ? { "Content-Range": `bytes ${a}-${b}/${st.size}` } : {}) });
    if (req.method === "HEAD") res.end();
    else fs.createReadStream(f, { start: a, end: b }).pipe(res);
  });
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const base = `http://127.0.0.1:${server.address().port}`;

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", `--window-size=${width},${height}`],
  defaultViewport: { width, height },
});
const problems = [];
const page = await browser.newPage();
page.on("console", async (m) => {
  if (m.text().startsWith("Player problem")) {
    const a = m.args()[2];
    const p = a ? await a.jsonValue().catch(() => undefined) : undefined;
    problems.push(p?.message ?? m.text());
  } else if (m.text().startsWith("BOOT")) {
    problems.push(m.text());
  }
});
page.on("pageerror", (e) => problems.push(`page error: ${e}`));
const url = `${base}/?ds=remote-file&ds.url=${encodeURIComponent(`${base}/log.mcap`)}&time=${encodeURIComponent(time)}`;
await page.goto(url, { waitUntil: "load" });
await new Promise((r) => setTimeout(r, wait * 1000));
await page.screenshot({ path: out });
await browser.close();
server.close();
for (const p of problems) console.error(`${log}: viewer problem: ${p}`);
console.log(`${out}: ${log} at k = ${k} (${time}) in Foxglove Studio 1.48.0; ${problems.length} problems`);
process.exit(problems.length ? 1 : 0);
