// Opens a rig report (report.html) in Debian's Chromium, headless, driven by
// playwright-core (pinned in package-lock.json), at a phone's width (390 px) and
// at a desktop's (1280 px), and prints what a reader would meet, as JSON:
// console errors and page errors, how far the page runs past the screen's
// width (a table or figure too wide must scroll inside its own box, never the
// page), the smallest rendered text in the figures and in the page, and the
// full-page screenshots it took.
//
//   node check_report.mjs REPORT.html SCREENSHOT_DIR
import { chromium } from "playwright-core";
import { mkdir } from "node:fs/promises";
import { pathToFileURL } from "node:url";
import path from "node:path";

const [report, shotDir] = process.argv.slice(2);
if (!report || !shotDir) {
  console.error("usage: node check_report.mjs REPORT.html SCREENSHOT_DIR");
  process.exit(2);
}
await mkdir(shotDir, { recursive: true });

// As the machine's notes say Chromium must start here: no sandbox as root, and
// none of its background connections (nothing may leave loopback).
const browser = await chromium.launch({
  executablePath: "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
const widths = [{ name: "phone", width: 390, height: 844 }, { name: "desktop", width: 1280, height: 900 }];
const result = {};
try {
  for (const view of widths) {
    const page = await browser.newPage({ viewport: { width: view.width, height: view.height } });
    const errors = [];
    page.on("console", (message) => { if (message.type() === "error") errors.push(message.text()); });
    page.on("pageerror", (error) => errors.push(String(error)));
    await page.goto(pathToFileURL(path.resolve(report)).href, { waitUntil: "load" });
    const measured = await page.evaluate(() => {
      const visible = (element) => {
        const box = element.getBoundingClientRect();
        return box.width > 0 && box.height > 0;
      };
      // A figure's text as drawn: its font size times the scale its SVG is shown at.
      let smallestFigureText = Infinity;
      let figureTexts = 0;
      for (const svg of document.querySelectorAll("svg")) {
        const shown = svg.getBoundingClientRect().width;
        const drawn = svg.viewBox.baseVal && svg.viewBox.baseVal.width > 0 ? svg.viewBox.baseVal.width : shown;
        const scale = drawn > 0 ? shown / drawn : 1;
        for (const text of svg.querySelectorAll("text")) {
          if (!visible(text) || text.textContent.trim() === "") continue;
          const size = parseFloat(getComputedStyle(text).fontSize) * scale;
          smallestFigureText = Math.min(smallestFigureText, size);
          figureTexts += 1;
        }
      }
      let smallestPageText = Infinity;
      for (const element of document.body.querySelectorAll("p, td, th, li, figcaption, h1, h2, h3, span, a, pre")) {
        if (!visible(element) || element.closest("svg")) continue;
        smallestPageText = Math.min(smallestPageText, parseFloat(getComputedStyle(element).fontSize));
      }
      return {
        overflowPx: document.documentElement.scrollWidth - window.innerWidth,
        smallestFigureTextPx: figureTexts > 0 ? smallestFigureText : null,
        figureTexts,
        figures: document.querySelectorAll("svg").length,
        tables: document.querySelectorAll("table").length,
        smallestPageTextPx: Number.isFinite(smallestPageText) ? smallestPageText : null,
      };
    });
    const screenshot = path.join(shotDir, `report-${view.width}px.png`);
    await page.screenshot({ path: screenshot, fullPage: true });
    result[view.name] = { width: view.width, errors, ...measured, screenshot };
    await page.close();
  }
} finally {
  await browser.close();
}
console.log(JSON.stringify(result));
