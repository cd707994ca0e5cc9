// SPDX-License-Identifier: GPL-3.0-or-later
// The participant page of `underfoot serve`: plain JavaScript, no build step, no libraries.
// Every text from the server is put in the page with textContent (never innerHTML), so it is
// always shown as text. The server decides the phase; this page shows it, plays the clips with
// WebAudio, and retries every request after a network error (answers carry an attempt id, so a
// retry never stores twice; a pending answer survives a reload in localStorage).
'use strict';

(() => {
  const token = decodeURIComponent((location.hash || '').replace(/^#/, ''));
  const page = document.getElementById('page');
  const net = document.getElementById('net');
  const progress = document.getElementById('progress');
  let audio = null;          // AudioContext, created on the first click or key (autoplay rules)
  let state = null;
  let keyHandler = null;
  let levelDone = false;     // the level page is shown once per page load, before the trials
  const clipCache = new Map();

  // ---------- small helpers ----------
  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v === undefined || v === null || v === false) continue;
      if (k === 'text') e.textContent = v;
      else if (k === 'class') e.className = v;
      else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v === true ? '' : String(v));
    }
    for (const c of children) if (c !== null && c !== undefined) e.append(c.nodeType ? c : String(c));
    return e;
  }
  function show(...nodes) {
    page.replaceChildren(...nodes);
    page.focus({ preventScroll: true });
    window.scrollTo(0, 0);
  }
  function onKeys(handler) { keyHandler = handler; }
  document.addEventListener('keydown', (ev) => {
    if (!keyHandler || ev.ctrlKey || ev.metaKey || ev.altKey) return;
    const t = ev.target;
    const typing = t && (t.tagName === 'TEXTAREA' || (t.tagName === 'INPUT' && t.type === 'text') || t.tagName === 'SELECT');
    if (typing && ev.key !== 'Enter') return;
    if (typing && t.tagName === 'TEXTAREA' && !ev.ctrlKey) return;
    if (keyHandler(ev) === true) ev.preventDefault();
  });
  function randomId() {
    const b = new Uint8Array(16);
    crypto.getRandomValues(b);
    return Array.from(b, (x) => x.toString(16).padStart(2, '0')).join('');
  }
  const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

  // ---------- the API, with retries ----------
  class Refused extends Error {
    constructor(status, message) { super(message); this.status = status; }
  }
  async function api(method, path, body, { binary = false } = {}) {
    let delay = 500;
    for (let attempt = 1; ; attempt++) {
      let res;
      try {
        res = await fetch(path, {
          method,
          headers: Object.assign({ Authorization: 'Bearer ' + token },
                                 body !== undefined ? { 'Content-Type': 'application/json' } : {}),
          body: body !== undefined ? JSON.stringify(body) : undefined,
          cache: 'no-store',
        });
      } catch (e) {
        res = null; // network error: the server is down or the connection dropped
      }
      if (res && res.status < 500 && res.status !== 429) {
        net.hidden = true;
        if (res.ok) return binary ? res.arrayBuffer() : res.json();
        let message = 'request refused (' + res.status + ')';
        try { message = (await res.json()).error || message; } catch (e) { /* not JSON */ }
        throw new Refused(res.status, message);
      }
      net.hidden = false;
      net.textContent = 'Connection problem; retrying (attempt ' + attempt + ')… Your answers are safe.';
      await sleep(delay);
      delay = Math.min(delay * 2, 5000);
    }
  }

  function ensureAudio() {
    if (!audio) {
      const Ctx = window.AudioContext || window.webkitAudioContext;
      audio = new Ctx();
      postClient();
    }
    if (audio.state === 'suspended') audio.resume();
    return audio;
  }
  // The audio output rate and (from the header) the user agent, once per page load and session.
  let clientPosted = false;
  function postClient() {
    if (clientPosted || !audio || !state || state.phase === 'consent') return;
    clientPosted = true;
    api('POST', '/api/client', { sampleRate: audio.sampleRate }).catch(() => { clientPosted = false; });
  }
  let playing = null;
  function playBuffer(buffer, gain = 1) {
    stopPlayback();
    const ctx = ensureAudio();
    const src = ctx.createBufferSource();
    src.buffer = buffer;
    const g = ctx.createGain();
    g.gain.value = gain;
    src.connect(g).connect(ctx.destination);
    src.start();
    playing = src;
    return new Promise((resolve) => { src.onended = () => { if (playing === src) playing = null; resolve(); }; });
  }
  function stopPlayback() {
    if (playing) { try { playing.stop(); } catch (e) { /* already stopped */ } playing = null; }
  }

  // ---------- rendering by phase ----------
  function render(s) {
    state = s;
    stopPlayback();
    document.getElementById('study-title').textContent = (s.study && s.study.title) || 'Listening test';
    progress.textContent = s.progress ? s.progress.answered + ' / ' + s.progress.total : '';
    postClient();
    switch (s.phase) {
      case 'consent': return consentPage(s);
      case 'screening': return screeningPage(s);
      case 'practice':
      case 'trial': return levelDone ? trialPage(s) : levelPage(s);
      case 'break': return breakPage(s);
      case 'finished': return finishedPage(s);
      default: return endedPage(s);
    }
  }
  async function refresh() { render(await api('GET', '/api/state')); }

  function errorBox() { return el('p', { class: 'error', role: 'alert' }); }

  function consentPage(s) {
    const err = errorBox();
    const fields = (s.fields || []).map((f) => {
      const id = 'field-' + f.id;
      const input = f.options && f.options.length
        ? el('select', { id, name: f.id, required: f.required },
             el('option', { value: '', text: '(choose)' }),
             ...f.options.map((o) => el('option', { value: o, text: o.replace(/_/g, ' ') })))
        : el('input', { id, name: f.id, type: 'text', required: f.required, maxlength: 200 });
      return el('p', {}, el('label', { for: id, text: f.label + (f.required ? '' : ' (optional)') }), input);
    });
    const agree = el('input', { type: 'checkbox', id: 'agree' });
    const form = el('form', { class: 'card', novalidate: true },
      el('h2', { text: 'About you' }),
      ...(fields.length ? fields : [el('p', { class: 'note', text: 'No questions.' })]),
      el('p', {}, el('label', { class: 'choice', for: 'agree' }, agree,
        'I have read the information above and agree to take part. I can stop at any time.')),
      err,
      el('button', { class: 'primary', type: 'submit', id: 'start', text: 'Start' }));
    form.addEventListener('submit', async (ev) => {
      ev.preventDefault();
      if (!agree.checked) { err.textContent = 'Please tick the box to agree first.'; agree.focus(); return; }
      const answers = {};
      for (const f of s.fields || []) answers[f.id] = form.elements[f.id].value;
      ensureAudio();
      try { render(await api('POST', '/api/consent', { consent: true, fields: answers })); }
      catch (e) { err.textContent = e.message; }
    });
    show(el('h1', { text: (s.study && s.study.title) || 'Listening test' }),
         el('div', { class: 'card' },
            el('h2', { text: 'Information' }),
            el('p', { class: 'lead', text: (s.study && s.study.briefing) || '' }),
            el('p', { text: 'Please use headphones in a quiet room. The test starts with a short headphone check and a volume setting.' })),
         form);
    onKeys(null);
  }

  // Woods, Siegel, Traer & McDermott (2017), Attention, Perception & Psychophysics 79:2064:
  // three 200 Hz tones, one 6 dB quieter; one of the two others is in antiphase between the
  // ears, which sounds quieter over loudspeakers but not over headphones. The server lays out
  // each triplet, renders its tones and scores the choices: the page only plays and forwards.
  function screeningPage(s) {
    if (!s.check || !s.check.started) {
      show(el('h1', { text: 'Headphone check' }), el('p', { text: 'Preparing…' }));
      api('POST', '/api/screening/start', {}).then(render)
        .catch((e) => show(el('h1', { text: 'Headphone check' }), el('p', { class: 'error', text: e.message })));
      return;
    }
    const total = s.check.triplets;
    let index = s.check.next;
    const status = el('p', { 'aria-live': 'polite' });
    const err = errorBox();
    const playBtn = el('button', { class: 'primary', type: 'button', text: 'Play the three sounds (Space)' });
    const choices = [1, 2, 3].map((n) => el('button', { type: 'button', disabled: true, 'data-choice': n },
      el('span', { class: 'key', text: String(n) }), ' Sound ' + n + ' was the quietest'));
    let busy = false;
    async function playTrial() {
      if (busy) return;
      busy = true;
      playBtn.disabled = true;
      choices.forEach((c) => { c.disabled = true; });
      err.textContent = '';
      try {
        const data = await api('GET', '/api/screening/tones/' + index, undefined, { binary: true });
        const buffer = await ensureAudio().decodeAudioData(data);
        // Three 1 s tones 0.5 s apart: name each one while it plays.
        const timers = [0, 1.5, 3].map((t, k) => setTimeout(() => { status.textContent = 'Sound ' + (k + 1); }, t * 1000));
        await playBuffer(buffer);
        timers.forEach(clearTimeout);
        status.textContent = 'Which sound was the quietest? (check ' + (index + 1) + ' of ' + total + ')';
        choices.forEach((c) => { c.disabled = false; });
        choices[0].focus();
      } catch (e) {
        err.textContent = e.message;
        playBtn.disabled = false;
      }
      busy = false;
    }
    async function choose(n) {
      if (choices[0].disabled) return;
      choices.forEach((c) => { c.disabled = true; });
      status.textContent = 'Saving…';
      let next;
      try { next = await api('POST', '/api/screening', { triplet: index, choice: n }); }
      catch (e) { err.textContent = e.message; playBtn.disabled = false; return; }
      if (next.phase !== 'screening' || !next.check) { render(next); return; }
      state = next;
      index = next.check.next;
      status.textContent = 'Check ' + (index + 1) + ' of ' + total + ': press Play.';
      playBtn.disabled = false;
      playBtn.focus();
    }
    playBtn.addEventListener('click', playTrial);
    choices.forEach((c) => c.addEventListener('click', () => choose(Number(c.dataset.choice))));
    show(el('h1', { text: 'Headphone check' }),
         el('div', { class: 'card' },
            el('p', { text: 'Put on your headphones. Each check plays three tones; press the number of the quietest one. There are ' + total + ' checks.' }),
            el('div', { class: 'row' }, playBtn), status, el('div', { class: 'row' }, ...choices), err));
    playBtn.focus();
    onKeys((ev) => {
      if (ev.key === ' ' && !playBtn.disabled) { playTrial(); return true; }
      if (['1', '2', '3'].includes(ev.key)) { choose(Number(ev.key)); return true; }
      return false;
    });
  }

  function levelPage(s) {
    let calibration = null;
    const playBtn = el('button', { type: 'button', text: 'Play the calibration sound (Space)' });
    const next = el('button', { class: 'primary', type: 'button', text: 'The level is comfortable: continue (Enter)' });
    async function play() {
      const ctx = ensureAudio();
      if (!calibration) {
        // 3 s of pink-ish noise in 250 ms bursts, at the level of a loud footstep clip.
        const rate = ctx.sampleRate, n = rate * 3;
        calibration = ctx.createBuffer(2, n, rate);
        const seed = new Uint32Array(1); crypto.getRandomValues(seed);
        let x = seed[0] || 1, b0 = 0, b1 = 0, b2 = 0;
        const l = calibration.getChannelData(0), r = calibration.getChannelData(1);
        for (let i = 0; i < n; i++) {
          x ^= x << 13; x ^= x >>> 17; x ^= x << 5; x >>>= 0;
          const w = x / 4294967296 * 2 - 1;
          b0 = 0.99765 * b0 + w * 0.0990460; b1 = 0.96300 * b1 + w * 0.2965164; b2 = 0.57000 * b2 + w * 1.0526913;
          const on = (i % Math.round(rate * 0.5)) < rate * 0.25 ? 1 : 0;
          l[i] = r[i] = 0.08 * on * (b0 + b1 + b2 + w * 0.1848);
        }
      }
      playBuffer(calibration);
    }
    function go() { stopPlayback(); levelDone = true; render(state); }
    playBtn.addEventListener('click', play);
    next.addEventListener('click', go);
    show(el('h1', { text: 'Set the volume' }),
         el('div', { class: 'card' },
            el('p', { text: 'Play the calibration sound and set your device volume so that it is clearly audible and comfortable. Do not change the volume during the test.' }),
            el('div', { class: 'row' }, playBtn, next)));
    playBtn.focus();
    onKeys((ev) => {
      if (ev.key === ' ') { play(); return true; }
      if (ev.key === 'Enter') { go(); return true; }
      return false;
    });
  }

  function pendingKey(trial) { return 'underfoot:' + token.slice(0, 12) + ':' + trial; }

  async function clipBuffer(trial) {
    if (!clipCache.has(trial)) {
      clipCache.clear();
      clipCache.set(trial, api('GET', '/api/clip/' + trial, undefined, { binary: true })
        .then((data) => ensureAudio().decodeAudioData(data)));
    }
    return clipCache.get(trial);
  }

  function trialPage(s) {
    const t = s.trial;
    const err = errorBox();
    let presented = t.presented, replays = t.replays, firstPlayAt = null, busy = false;
    // A pending answer of this trial (sent, not acknowledged before a reload): send it again.
    const saved = localStorage.getItem(pendingKey(t.index));
    if (saved) { submit(JSON.parse(saved)); return; }
    clipBuffer(t.index).catch((e) => { err.textContent = 'The sound could not be loaded: ' + e.message; });

    const playBtn = el('button', { class: 'primary', type: 'button', id: 'play' });
    const replayInfo = el('span', { class: 'note', 'aria-live': 'polite' });
    function updatePlay() {
      playBtn.textContent = presented ? 'Play again (Space)' : 'Play (Space)';
      playBtn.disabled = presented && !t.replayAllowed;
      replayInfo.textContent = presented && !t.replayAllowed ? 'This sound can be played only once.'
        : replays > 0 ? 'Played again ' + replays + (replays === 1 ? ' time' : ' times') : '';
    }
    async function play() {
      if (busy || (presented && !t.replayAllowed)) return;
      busy = true;
      try {
        const buffer = await clipBuffer(t.index);
        const r = await api('POST', '/api/present', { trial: t.index, attempt: randomId() });
        if (presented) replays = r.replays;
        presented = true;
        if (firstPlayAt === null) firstPlayAt = performance.now();
        updatePlay();
        form.hidden = false;
        playBuffer(buffer);
      } catch (e) {
        err.textContent = e.message;
      } finally { busy = false; }
    }
    playBtn.addEventListener('click', play);
    updatePlay();

    const form = el('form', { class: 'card', novalidate: true, hidden: !presented });
    const keyed = new Map();
    function radioGroup(name, options) {
      return el('div', { class: 'options', role: 'radiogroup' }, ...options.map((o) => {
        const input = el('input', { type: 'radio', name, value: o.id });
        if (o.key) keyed.set(o.key, input);
        return el('label', { class: 'choice' }, input, o.key ? el('span', { class: 'key', text: o.key }) : null, o.label);
      }));
    }
    if (t.surface) form.append(el('h2', { text: t.surface.prompt }), radioGroup('answer', t.surface.options));
    const digitScale = t.scales.length === 1 && t.scales[0].min >= 0 && t.scales[0].max <= 9 && !t.surface;
    for (const sc of t.scales) {
      const values = [];
      for (let v = sc.min; v <= sc.max; v++) values.push(v);
      const anchorOf = new Map(sc.anchors.map((a) => [a.value, a.label]));
      form.append(el('h2', { text: sc.prompt }),
        el('div', { class: 'scale', role: 'radiogroup', 'aria-label': sc.prompt }, ...values.map((v) =>
          el('label', { class: 'choice', title: anchorOf.get(v) || '' },
             el('input', { type: 'radio', name: 'scale:' + sc.id, value: v }), String(v)))),
        el('div', { class: 'anchors' }, el('span', { text: sc.min + ': ' + (anchorOf.get(sc.min) || sc.minLabel || '') }),
                                         el('span', { text: sc.max + ': ' + (anchorOf.get(sc.max) || sc.maxLabel || '') })));
      const middle = sc.anchors.filter((a) => a.value !== sc.min && a.value !== sc.max);
      if (middle.length) form.append(el('ul', { class: 'anchor-list' }, ...middle.map((a) => el('li', { text: a.value + ': ' + a.label }))));
    }
    if (t.soundscape) form.append(el('h2', { text: t.soundscape.prompt }),
      radioGroup('soundscape', t.soundscape.options.map((o) => Object.assign({}, o, { key: null }))));
    let comment = null;
    if (t.comment) {
      comment = el('textarea', { id: 'comment', rows: 2, maxlength: 2000 });
      form.append(el('h2', {}, el('label', { for: 'comment', text: 'Comment (optional)' })), comment);
    }
    const next = el('button', { class: 'primary', type: 'submit', id: 'next', text: 'Next (Enter)' });
    form.append(err, el('div', { class: 'row' }, next));
    form.addEventListener('submit', (ev) => {
      ev.preventDefault();
      const a = { trial: t.index, attempt: randomId(), participant: s.participant, ratings: {} };
      const checked = (name) => { const c = form.querySelector('input[name="' + CSS.escape(name) + '"]:checked'); return c ? c.value : null; };
      if (t.surface) { a.answer = checked('answer'); if (!a.answer) { err.textContent = 'Please choose an answer.'; return; } }
      for (const sc of t.scales) {
        const v = checked('scale:' + sc.id);
        if (v === null) { err.textContent = 'Please answer every question.'; return; }
        a.ratings[sc.id] = Number(v);
      }
      if (t.soundscape) { a.soundscape = checked('soundscape'); if (!a.soundscape) { err.textContent = 'Please choose an environment.'; return; } }
      if (comment && comment.value.trim()) a.comment = comment.value.trim();
      a.clientMs = Math.max(0, Math.round((performance.now() - (firstPlayAt ?? performance.now())) * 10) / 10);
      localStorage.setItem(pendingKey(t.index), JSON.stringify(a));
      submit(a);
    });

    // The heading ("Trial 3 of 40", "Practice trial 1 of 40") is the trial core's.
    show(el('h1', { text: t.heading }),
         el('div', { class: 'card' }, el('p', { text: t.practice ? 'A practice sound: it is not part of the results.' : 'Listen, then answer.' }),
            el('div', { class: 'row' }, playBtn, replayInfo)),
         form);
    playBtn.focus();
    onKeys((ev) => {
      // Space plays unless a control has the focus (Space checks a radio / presses a button).
      if (ev.key === ' ' && !['INPUT', 'BUTTON', 'TEXTAREA', 'SELECT'].includes(ev.target.tagName)) { play(); return true; }
      if (ev.key === ' ') return false;
      if (form.hidden) return false;
      const k = ev.key.toLowerCase();
      if (keyed.has(k) && ev.target.tagName !== 'TEXTAREA') { keyed.get(k).checked = true; keyed.get(k).focus(); return true; }
      if (digitScale && /^[0-9]$/.test(ev.key)) {
        const input = form.querySelector('input[name="scale:' + CSS.escape(t.scales[0].id) + '"][value="' + ev.key + '"]');
        if (input) { input.checked = true; input.focus(); return true; }
      }
      if (ev.key === 'Enter' && ev.target.tagName !== 'BUTTON') { form.requestSubmit(); return true; }
      return false;
    });
  }

  async function submit(a) {
    show(el('p', { text: 'Saving your answer…' }));
    onKeys(null);
    try {
      const r = await api('POST', '/api/answer', a);
      localStorage.removeItem(pendingKey(a.trial));
      render(r);
    } catch (e) {
      localStorage.removeItem(pendingKey(a.trial));
      if (e.status === 409) { await refresh(); return; } // already answered or not current: go on
      show(el('p', { class: 'error', text: e.message }),
           el('button', { type: 'button', class: 'primary', text: 'Continue', onclick: () => refresh() }));
    }
  }

  function breakPage(s) {
    const go = el('button', { class: 'primary', type: 'button', text: 'Continue (Enter)' });
    async function next() { go.disabled = true; render(await api('POST', '/api/break', {})); }
    go.addEventListener('click', next);
    show(el('h1', { text: 'Break' }),
         el('div', { class: 'card' }, el('p', { text: 'Take a short rest. Continue when you are ready.' }), go));
    go.focus();
    onKeys((ev) => { if (ev.key === 'Enter' && ev.target !== go) { next(); return true; } return false; });
  }

  function finishedPage(s) {
    show(el('h1', { text: 'Thank you!' }),
         el('div', { class: 'card' },
            el('p', { text: 'You have completed the test. Your completion code is:' }),
            el('p', {}, el('span', { class: 'code', id: 'completion-code', text: s.completionCode || '' })),
            el('p', { class: 'note', text: 'You can close this page now.' })));
    onKeys(null);
  }

  function endedPage(s) {
    show(el('h1', { text: 'The test has ended' }),
         el('div', { class: 'card' }, el('p', {
           text: s.reason === 'screening'
             ? 'The headphone check showed that the sounds cannot be heard as intended on your device. Thank you for your time.'
             : 'This participation has been closed by the experimenter. Thank you for your time.' })));
    onKeys(null);
  }

  async function start() {
    if (!/^[A-Za-z0-9_-]{43}$/.test(token)) {
      show(el('h1', { text: 'Invalid link' }), el('p', { text: 'Please open the exact link you received.' }));
      return;
    }
    try { await refresh(); }
    catch (e) { show(el('h1', { text: 'This link cannot be used' }), el('p', { class: 'error', text: e.message })); }
  }
  window.addEventListener('hashchange', () => location.reload());
  start();
})();
