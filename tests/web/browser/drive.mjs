// SPDX-License-Identifier: GPL-3.0-or-later
// Takes one participant through the page of `underfoot serve` in headless Chromium (Debian's
// chromium, driven over the DevTools protocol by puppeteer-core), with the keyboard only:
// consent -> headphone screening -> level -> practice -> trials (with breaks) -> completion
// code. The screening is answered from what the page actually plays (the peak of each tone
// in the triplet the server rendered, read by wrapping AudioBufferSourceNode.start): the server
// scores it, so a page or server playing the wrong levels fails the check. Screenshots of each page go to the given folder.
//
//   node drive.mjs LINK SCREENSHOT_DIR NAME CHROMIUM [RESULT_JSON]
import puppeteer from 'puppeteer-core';
import fs from 'node:fs';
import path from 'node:path';

const [link, shotDir, name, chromium, resultFile] = process.argv.slice(2);
if (!link || !shotDir || !name || !chromium) {
  console.error('usage: node drive.mjs LINK SCREENSHOT_DIR NAME CHROMIUM [RESULT_JSON]');
  process.exit(2);
}
fs.mkdirSync(shotDir, { recursive: true });
const started = Date.now();
const deadline = started + 240_000;
const pageErrors = [];
const answerTimes = [];

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--autoplay-policy=no-user-gesture-required',
         '--disable-dev-shm-usage', '--mute-audio'],
});
let exitCode = 0;
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 390, height: 844, deviceScaleFactor: 1, isMobile: true, hasTouch: true });
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') pageErrors.push(m.text()); });
  // Answer round trip seen by the browser: POST /api/answer request -> response.
  const sentAt = new Map();
  page.on('request', (r) => { if (r.url().endsWith('/api/answer')) sentAt.set(r, performance.now()); });
  page.on('response', (r) => {
    const q = r.request();
    if (sentAt.has(q)) { answerTimes.push(performance.now() - sentAt.get(q)); sentAt.delete(q); }
  });
  await page.evaluateOnNewDocument(() => {
    window.__played = [];
    const start = AudioBufferSourceNode.prototype.start;
    AudioBufferSourceNode.prototype.start = function (...args) {
      const b = this.buffer;
      if (b) {
        const d = b.getChannelData(0);
        let peak = 0;
        for (let i = 0; i < d.length; i++) peak = Math.max(peak, Math.abs(d[i]));
        // Peaks of the left ear in three equal windows (one tone each in a headphone-check
        // triplet), as a listener with headphones hears them.
        const thirds = [0, 1, 2].map((k) => {
          let p = 0;
          for (let i = Math.floor(k * d.length / 3); i < Math.floor((k + 1) * d.length / 3); i++) p = Math.max(p, Math.abs(d[i]));
          return p;
        });
        window.__played.push({ peak, thirds, seconds: b.duration, channels: b.numberOfChannels });
      }
      return start.apply(this, args);
    };
  });

  const shots = new Set();
  async function shot(label) {
    if (shots.has(label)) return;
    shots.add(label);
    await page.screenshot({ path: path.join(shotDir, `${name}-${label}.png`), fullPage: true });
  }
  async function heading() {
    return page.$eval('h1', (h) => h.textContent).catch(() => '');
  }
  async function tabTo(predicateSource, what) {
    for (let i = 0; i < 80; i++) {
      const ok = await page.evaluate(predicateSource);
      if (ok) return;
      await page.keyboard.press('Tab');
    }
    throw new Error(`could not reach ${what} with Tab`);
  }
  async function waitFor(fn, what, timeout = 30_000, ...args) {
    await page.waitForFunction(fn, { timeout, polling: 50 }, ...args)
      .catch(() => { throw new Error(`timed out waiting for ${what}`); });
  }

  await page.goto(link, { waitUntil: 'load' });
  await waitFor(() => !!document.querySelector('#start'), 'the consent page');
  // The protocol's texts are shown as text, never as markup.
  const injected = await page.evaluate(() => document.querySelectorAll('main script, main b').length);
  if (injected) throw new Error('protocol text was inserted as HTML');
  await shot('1-consent');

  // Consent: every participant field by keyboard (first option), the box, then Start.
  const fields = await page.$$eval('main select, main input[type=text]', (els) => els.map((e) => e.id));
  for (const id of fields) {
    await tabTo(`document.activeElement && document.activeElement.id === ${JSON.stringify(id)}`, id);
    const tag = await page.evaluate(() => document.activeElement.tagName);
    if (tag === 'SELECT') await page.keyboard.press('ArrowDown');
    else await page.keyboard.type('n/a');
  }
  await tabTo(`document.activeElement && document.activeElement.id === 'agree'`, 'the consent box');
  await page.keyboard.press('Space');
  await tabTo(`document.activeElement && document.activeElement.id === 'start'`, 'Start');
  await page.keyboard.press('Enter');

  // Headphone screening: 6 checks of three tones; press the number of the quietest one.
  await waitFor(() => document.querySelector('h1')?.textContent === 'Headphone check', 'the screening');
  await shot('2-screening');
  for (let check = 0; check < 6; check++) {
    // The previous choice is stored (and scored) by the server before Play is enabled again.
    await waitFor(() => [...document.querySelectorAll('button')]
      .some((b) => b.textContent.startsWith('Play the three') && !b.disabled), 'the play button');
    const before = await page.evaluate(() => window.__played.length);
    await page.keyboard.press('Space');
    await waitFor((n) => window.__played.length >= n + 1 && !document.querySelector('[data-choice]').disabled,
      'three tones', 15_000, before);
    const peaks = await page.evaluate((n) => window.__played[n].thirds, before);
    const quiet = peaks.indexOf(Math.min(...peaks));
    const ratio = Math.min(...peaks) / Math.max(...peaks);
    if (Math.abs(20 * Math.log10(ratio) + 6) > 0.5) throw new Error(`the quiet tone is not 6 dB down: ${peaks}`);
    if (check === 0) await shot('2b-screening-answer');
    await page.keyboard.press(String(quiet + 1));
  }

  // Level page, then trials until the completion code.
  await waitFor(() => document.querySelector('h1')?.textContent === 'Set the volume', 'the level page');
  await page.keyboard.press('Space');
  await shot('3-level');
  await page.keyboard.press('Enter');

  let trials = 0, reloaded = false;
  while (Date.now() < deadline) {
    if (trials === 2 && !reloaded) { // a reload mid-test resumes at the first unanswered trial
      reloaded = true;
      await page.reload({ waitUntil: 'load' });
    }
    await waitFor(() => ['Thank you!', 'Break', 'Set the volume'].includes(document.querySelector('h1')?.textContent)
      || /^(Practice trial|Trial) \d+ of \d+$/.test(document.querySelector('h1')?.textContent || ''), 'the next page');
    const h = await heading();
    if (h === 'Thank you!') { await shot('9-end'); break; }
    if (h === 'Set the volume') { await page.keyboard.press('Enter'); await waitFor(() => document.querySelector('h1')?.textContent !== 'Set the volume', 'the trials after the reload'); continue; }
    if (h === 'Break') { await shot('6-break'); await page.keyboard.press('Enter'); await waitFor(() => document.querySelector('h1')?.textContent !== 'Break', 'the end of the break'); continue; }
    const label = h.startsWith('Practice') ? '4-practice' : '5-trial';
    await waitFor(() => document.activeElement && document.activeElement.id === 'play', 'the play button');
    await page.keyboard.press('Space'); // play (presented, stored, then heard)
    await waitFor(() => !document.querySelector('main form').hidden, 'the questions');
    // One replay where the protocol allows it (counted by the server).
    const replayable = await page.evaluate(() => !document.querySelector('#play').disabled);
    if (replayable && trials === 1) {
      await page.evaluate(() => document.querySelector('#play').focus());
      await page.keyboard.press('Space');
      await waitFor(() => /Played again 1 time/.test(document.querySelector('main').textContent), 'the replay count');
    }
    // Answer: the option letter, then each scale by Tab + arrows (a different value per trial).
    const plan = await page.evaluate(() => ({
      letters: [...document.querySelectorAll('main .options .key')].map((k) => k.textContent),
      scales: [...new Set([...document.querySelectorAll('main input[type=radio][name^="scale:"]')].map((i) => i.name))],
      soundscape: !!document.querySelector('main input[name=soundscape]'),
      comment: !!document.querySelector('#comment'),
    }));
    if (plan.letters.length) await page.keyboard.press(plan.letters[trials % plan.letters.length]);
    for (const scale of plan.scales) {
      await tabTo(`document.activeElement && document.activeElement.name === ${JSON.stringify(scale)}`, scale);
      await page.keyboard.press('Space');
      for (let k = 0; k < (trials % 3) + 1; k++) await page.keyboard.press('ArrowRight');
    }
    if (plan.soundscape) {
      await tabTo(`document.activeElement && document.activeElement.name === 'soundscape'`, 'soundscape');
      await page.keyboard.press('Space');
    }
    if (plan.comment && trials === 0) {
      await tabTo(`document.activeElement && document.activeElement.id === 'comment'`, 'the comment');
      await page.keyboard.type('<i>not markup</i> & fine');
    }
    await shot(label);
    await tabTo(`document.activeElement && document.activeElement.id === 'next'`, 'Next');
    // Only the one deliberate replay was counted (keys used to answer never replay).
    const shownReplays = await page.evaluate(() => (document.querySelector('main').textContent.match(/Played again (\d+)/) || [0, '0'])[1]);
    if (Number(shownReplays) !== (replayable && trials === 1 ? 1 : 0)) throw new Error(`unexpected replays: ${shownReplays}`);
    const answered = await page.evaluate(() => document.querySelector('#progress').textContent);
    await page.keyboard.press('Enter');
    await waitFor((was) => document.querySelector('#progress').textContent !== was, 'the acknowledgement', 30_000, answered);
    trials++;
  }
  const code = await page.$eval('#completion-code', (e) => e.textContent).catch(() => '');
  if (!/^[A-Z2-9]{10}$/.test(code)) throw new Error(`no completion code (got '${code}')`);
  if (pageErrors.length) throw new Error('errors in the page: ' + pageErrors.join('; '));
  answerTimes.sort((a, b) => a - b);
  const result = {
    name, trials, completionCode: code, seconds: (Date.now() - started) / 1000,
    answerRoundTripMs: { median: answerTimes[Math.floor(answerTimes.length / 2)], max: answerTimes[answerTimes.length - 1] },
    screenshots: [...shots].map((s) => `${name}-${s}.png`),
  };
  console.log(JSON.stringify(result));
  if (resultFile) fs.writeFileSync(resultFile, JSON.stringify(result, null, 2));
} catch (e) {
  console.error(`${name}: ${e.message}`);
  if (pageErrors.length) console.error('page errors: ' + pageErrors.join('; '));
  try {
    const pages = await browser.pages();
    await pages[pages.length - 1].screenshot({ path: path.join(shotDir, `${name}-FAILED.png`), fullPage: true });
  } catch (_) { /* no page */ }
  exitCode = 1;
} finally {
  await browser.close();
}
process.exit(exitCode);
