// Screenshot of view.html (CesiumJS drawing tiles/tileset.json) in headless Chromium.
// Usage: node shot.mjs [?range=M&pitch=DEG] [out.png]
import { chromium } from 'playwright-core';
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: ['--headless', '--no-sandbox', '--disable-gpu', '--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run'] });
const page = await browser.newPage({ viewport: { width: 1024, height: 700 } });
page.on('console', m => { if (m.type() === 'error') console.log('console:', m.text()); });
await page.goto(`http://127.0.0.1:${process.env.PORT || 8765}/view.html` + (process.argv[2] || ''));
await page.waitForFunction(() => document.title.startsWith('READY') || document.title.startsWith('ERROR'), null, { timeout: 240000 });
console.log(await page.title());
await page.screenshot({ path: process.argv[3] || 'shot.png' });
await browser.close();
