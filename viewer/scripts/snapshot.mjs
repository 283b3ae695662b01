// Loads the page of `grammarc view` in headless Chromium and reports what it shows:
//   node snapshot.mjs URL OUT.png [SECONDS] [WIDTHxHEIGHT]
// waits until the page's tiles have settled (or 120 s), counts frames for SECONDS (default 3), clicks from
// the middle outwards until a click shows a feature, takes a screenshot (default 1280x800, the feature's
// panel in it) and prints one JSON line: tilesLoaded, tilesVisible, triangles, loadSeconds (from navigation
// to the last tile loaded), fps, picked (the panel's text, or null), error. The browser is CHROMIUM, else
// /usr/bin/chromium (Debian's package).
import { chromium } from "playwright-core";

const [url, out, seconds = "3", size = "1280x800"] = process.argv.slice(2);
const [width, height] = size.split("x").map(Number);
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  // WebGL on the CPU (SwiftShader): CI machines have no GPU
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
         "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run"],
});
try {
  const page = await browser.newPage({ viewport: { width, height } });
  const errors = [];
  page.on("pageerror", (error) => errors.push(String(error)));
  await page.goto(url);
  await page.waitForFunction(() => window.viewer && (window.viewer.settledAt !== null || window.viewer.error),
                             null, { timeout: 120000, polling: 250 });
  const first = await page.evaluate(() => ({ frames: window.viewer.frames, at: performance.now() }));
  await page.waitForTimeout(Number(seconds) * 1000);
  const state = await page.evaluate(() => ({ ...window.viewer, at: performance.now() }));
  let picked = null;
  for (let ring = 0; ring < 6 && picked === null; ring += 1) {
    for (let k = 0; k < Math.max(1, 8 * ring) && picked === null; k += 1) {
      const angle = (2 * Math.PI * k) / Math.max(1, 8 * ring);
      await page.mouse.click(width / 2 + ring * 40 * Math.cos(angle), height / 2 + ring * 40 * Math.sin(angle));
      picked = await page.evaluate(() => (document.getElementById("info").hidden ? null : document.getElementById("info").innerText));
    }
  }
  await page.screenshot({ path: out });
  console.log(JSON.stringify({
    tilesLoaded: state.tilesLoaded, tilesVisible: state.tilesVisible, triangles: state.triangles,
    loadSeconds: state.settledAt / 1000, fps: ((state.frames - first.frames) * 1000) / (state.at - first.at), picked,
    error: state.error ?? (errors.length ? errors.join("; ") : null),
  }));
} finally {
  await browser.close();
}
