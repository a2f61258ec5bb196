// node scripts/screenshot.mjs URL OUT.png [--wait-idle SECONDS] [--width W --height H]
// Opens the editor in Debian's headless Chromium (/usr/bin/chromium, or $CHROMIUM) and saves a screenshot once
// the app reports data-state="idle" (or the wait runs out). Logs the page's console errors.
import { chromium } from 'playwright-core';

const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : fallback;
};
const [url, out] = args;
if (!url || !out) {
  console.error('usage: node scripts/screenshot.mjs URL OUT.png [--wait-idle S] [--width W] [--height H] [--click SELECTOR] [--overview OUT2.png]');
  process.exit(2);
}
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', args: ['--no-sandbox'] });
const page = await browser.newPage({ viewport: { width: Number(opt('--width', 1600)), height: Number(opt('--height', 900)) } });
page.on('console', (m) => m.type() === 'error' && console.error('console:', m.text()));
page.on('pageerror', (e) => console.error('pageerror:', e.message));
await page.goto(url);
const waitS = Number(opt('--wait-idle', 60));
const started = Date.now();
try {
  await page.waitForSelector('[data-testid="app"][data-state="busy"]', { timeout: 3000 }).catch(() => undefined);
  await page.waitForSelector('[data-testid="app"][data-state="idle"]', { timeout: waitS * 1000 });
  console.log(`idle after ${((Date.now() - started) / 1000).toFixed(1)} s`);
} catch {
  console.log(`still busy after ${waitS} s`);
}
const click = opt('--click', undefined);
if (click) {
  await page.click(click);
  await page.waitForTimeout(Number(opt('--after-click-ms', 3000)));
}
await page.screenshot({ path: out });
// --overview OUT2.png: also the whole graph (React Flow's fit-view control).
const overview = opt('--overview', undefined);
if (overview) {
  await page.click('.react-flow__controls-fitview');
  await page.waitForTimeout(800);
  await page.screenshot({ path: overview });
}
await browser.close();
