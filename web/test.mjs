// The page's headless browser run, driven by `cargo xtask test` (xtask/src/web_test.rs):
// serves target/web/ on localhost, opens each case's URL in Debian's Chromium (WebGPU on
// SwiftShader), waits for the page to say `done` or `error`, and writes what it saw: the
// last frame's pixels (`<case>.png`, read from the canvas by the page itself), the page's
// state and message, every console error or warning and every uncaught exception, and the
// time from navigation to the page's `done` (or `running`, for the cases that act on it). Judging is left to xtask (it compares the
// frames with native renders); this script only records.
//
// usage: node web/test.mjs CASES.json OUT_DIR
//   CASES.json: {"site": "target/web", "cases": [{"name", "query", "webgpu", "viewport",
//                "until", "files", "downloadKey", "measure", "screenshot"}]}
//   `measure`: a lab matrix (JSON) the running page's measure panel runs; its bench.json
//   is written as `<case>-bench.json`.

import { chromium } from "playwright-core";
import { createServer } from "node:http";
import { readFile, writeFile, mkdir } from "node:fs/promises";
import { extname, join, normalize } from "node:path";

const [casesFile, outDir] = process.argv.slice(2);
const { site, cases, chromium: executablePath, timeoutMs, workers = 1 } = JSON.parse(await readFile(casesFile, "utf8"));
await mkdir(outDir, { recursive: true });

const types = {
  ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm",
  ".gltf": "model/gltf+json", ".bin": "application/octet-stream", ".jpg": "image/jpeg",
  ".png": "image/png", ".md": "text/markdown",
};
const server = createServer(async (request, response) => {
  try {
    const path = normalize(decodeURIComponent(new URL(request.url, "http://x").pathname));
    const body = await readFile(join(site, path.endsWith("/") ? `${path}index.html` : path));
    response.writeHead(200, { "content-type": types[extname(path)] ?? "application/octet-stream" });
    response.end(body);
  } catch {
    response.writeHead(404);
    response.end();
  }
});
await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
const base = `http://127.0.0.1:${server.address().port}/index.html`;

// WebGPU on SwiftShader with a canvas that reads back (docs: ../shared/REFERENCES.md).
const webgpuFlags = [
  "--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader",
  "--use-angle=vulkan", "--enable-unsafe-swiftshader",
];
// Chromium refuses to run as root with its sandbox (CI runs as root).
const common = process.getuid?.() === 0 ? ["--no-sandbox"] : [];

// `workers` cases run side by side, each worker with browsers of its own (one browser's GPU
// process serves its pages one at a time). On CI's 2 cores this bought little, since
// SwiftShader keeps both busy (docs/testing.md has the numbers); with more cores, more.
async function worker(queue, results) {
  const browsers = {};
  const browser = async (webgpu) => {
    const key = webgpu ? "webgpu" : "plain";
    browsers[key] ??= await chromium.launch({
      executablePath,
      args: [...common, ...(webgpu ? webgpuFlags : [])],
    });
    return browsers[key];
  };
  for (let next = queue.shift(); next; next = queue.shift()) {
    results[next.index] = await runCase(next.testCase, browser);
  }
  for (const open of Object.values(browsers)) await open.close();
}

async function runCase(testCase, browser) {
  const viewport = testCase.viewport ?? { width: 320, height: 240 };
  const context = await (await browser(testCase.webgpu)).newContext({ viewport, deviceScaleFactor: 1 });
  const page = await context.newPage();
  const messages = [];
  // Everything the page printed, kept whole for a failed case's folder (xtask's web_test).
  const consoleLog = [];
  page.on("console", (message) => {
    consoleLog.push(`console.${message.type()}: ${message.text()}`);
    if (["error", "warning"].includes(message.type())) messages.push(`console.${message.type()}: ${message.text()}`);
  });
  page.on("pageerror", (error) => {
    consoleLog.push(`uncaught: ${error}`);
    messages.push(`uncaught: ${error}`);
  });
  const started = Date.now();
  await page.goto(`${base}?${testCase.query}`);
  let state = "timeout";
  try {
    await page.waitForFunction(
      (wanted) => wanted.includes(document.body.dataset.state),
      testCase.until ?? ["done", "error"],
      { timeout: timeoutMs },
    );
    state = await page.evaluate(() => document.body.dataset.state);
  } catch (error) {
    messages.push(`the page did not finish within ${timeoutMs} ms: ${error.message.split("\n")[0]}`);
  }
  const elapsedMs = Date.now() - started;
  // A user's own files, opened with the page's file picker once it runs.
  let scene = null;
  let loadError = null;
  if (testCase.files && state === "running") {
    await page.setInputFiles("#open-files", testCase.files);
    try {
      await page.waitForFunction(
        () => document.body.dataset.scene || document.body.dataset.loadError,
        null,
        { timeout: timeoutMs },
      );
    } catch (error) {
      messages.push(`the opened files neither loaded nor failed within ${timeoutMs} ms`);
    }
    // Error scopes report asynchronously: give the new scene a few frames to say anything.
    await page.waitForTimeout(1000);
    scene = await page.evaluate(() => document.body.dataset.scene ?? null);
    loadError = await page.evaluate(() => document.body.dataset.loadError ?? null);
  }
  // A key pressed on the running page whose result is a download (F12: the screenshot).
  let download = null;
  if (testCase.downloadKey && state === "running") {
    await page.click("canvas#manylights");
    const waiting = page.waitForEvent("download", { timeout: timeoutMs });
    await page.keyboard.press(testCase.downloadKey);
    try {
      const file = await waiting;
      download = join(outDir, `${testCase.name}-download.png`);
      await file.saveAs(download);
    } catch (error) {
      messages.push(`pressing ${testCase.downloadKey} downloaded nothing: ${error.message.split("\n")[0]}`);
    }
  }
  // The measure panel's run of a small matrix on the running page.
  let measure = null;
  let measureError = null;
  let errorMaps = null;
  let bench = null;
  if (testCase.measure && state === "running") {
    try {
      await page.evaluate((matrix) => window.manylightsMeasure(matrix), JSON.stringify(testCase.measure));
      await page.waitForFunction(
        () => ["done", "error"].includes(document.body.dataset.measure),
        null,
        { timeout: timeoutMs },
      );
    } catch (error) {
      messages.push(`the measurement did not end within ${timeoutMs} ms: ${String(error).split("\n")[0]}`);
    }
    measure = await page.evaluate(() => document.body.dataset.measure ?? null);
    measureError = await page.evaluate(() => document.body.dataset.measureError ?? null);
    errorMaps = await page.evaluate(() => document.querySelectorAll("#measure img.error-map").length);
    const json = await page.evaluate(() => window.manylightsBench ?? null);
    if (json) {
      bench = join(outDir, `${testCase.name}-bench.json`);
      await writeFile(bench, json);
    }
  }
  const status = await page.evaluate(() => document.getElementById("status")?.textContent ?? "");
  const frame = await page.evaluate(() => window.manylightsFrame ?? null);
  if (frame) {
    await writeFile(join(outDir, `${testCase.name}.png`), Buffer.from(frame.split(",")[1], "base64"));
  }
  // A photograph of the page for the docs. Playwright waits for the compositor's next frame,
  // which on a loaded 2-core machine (SwiftShader still busy with the measure panel's last
  // frames) can take longer than its 30 s default: give it the case's budget, and record a
  // failure as this case's message instead of ending the whole run.
  if (testCase.screenshot) {
    try {
      await page.screenshot({ path: join(outDir, `${testCase.name}-page.png`), timeout: timeoutMs });
    } catch (error) {
      messages.push(`the page's screenshot failed: ${error.message.split("\n")[0]}`);
    }
  }
  console.log(`${testCase.name}: ${state} in ${elapsedMs} ms${messages.length ? ` (${messages.length} messages)` : ""}`);
  await context.close();
  return {
    name: testCase.name, state, status, messages, console: consoleLog, elapsed_ms: elapsedMs, frame: Boolean(frame),
    scene, load_error: loadError, download, measure, measure_error: measureError, bench,
    error_maps: errorMaps,
    measure_ms: testCase.measure ? Date.now() - started - elapsedMs : null,
  };
}

const results = new Array(cases.length);
// The long cases (the measure panel's run, the full-size page) start first, so the short
// ones fill the other worker around them.
const long = (testCase) => (testCase.measure ? 2 : 0) + (testCase.screenshot ? 1 : 0);
const queue = cases
  .map((testCase, index) => ({ testCase, index }))
  .sort((a, b) => long(b.testCase) - long(a.testCase));
await Promise.all(Array.from({ length: Math.max(1, workers) }, () => worker(queue, results)));
server.close();
await writeFile(join(outDir, "results.json"), JSON.stringify(results, null, 2));
