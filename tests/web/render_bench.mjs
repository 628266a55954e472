// render_bench.mjs - the jobs page in Debian's chromium against a server with many jobs (run by
// bench/web.sh): signs in with WEB_ADMIN, opens #/jobs, then pages forward PAGES times; prints the
// time from each navigation to its rows shown, the server's answer time the page measured, and
// the longest task the page ran ("long task" entries of at least 50 ms; none means no freeze a
// user could notice). Figures only: nothing is asserted.
import { chromium } from 'playwright-core';

const url = process.env.WEB_URL, PAGES = 5;
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync'] });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  await page.addInitScript(() => {
    window.__long = [];
    new PerformanceObserver((l) => { for (const e of l.getEntries()) window.__long.push(e.duration); })
      .observe({ type: 'longtask', buffered: true });
  });
  await page.goto(url + '/');
  await page.fill('#token', process.env.WEB_ADMIN);
  await page.click('#signin-button');
  await page.waitForSelector('#jobs');
  const times = [];
  for (let i = 0; i <= PAGES; i++) {
    const t0 = Date.now();
    if (i) await page.click('#next');
    else await page.goto(url + '/#/jobs');
    await page.waitForFunction((n) => document.querySelectorAll('#jobs-rows tr').length === 100 &&
      document.querySelector('#page-number').textContent === `page ${n}` && document.querySelector('#jobs-status').textContent.includes('ms'), i + 1);
    const status = await page.textContent('#jobs-status');
    times.push({ shown: Date.now() - t0, answer: Number(/\((\d+) ms\)/.exec(status)[1]) });
  }
  const long = await page.evaluate(() => window.__long);
  const med = (a) => a.slice().sort((x, y) => x - y)[Math.floor(a.length / 2)];
  console.log(`jobs page in chromium, pages of 100 among the jobs: rows shown ${med(times.map((t) => t.shown))} ms after a click ` +
    `(median of ${times.length}; each ${times.map((t) => t.shown).join(', ')} ms), the API's answer as the page measured it ` +
    `${med(times.map((t) => t.answer))} ms; long tasks: ${long.length ? long.length + ', the longest ' + Math.round(Math.max(...long)) + ' ms' : 'none'}`);
} finally {
  await browser.close();
}
