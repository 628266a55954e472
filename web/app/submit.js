// submit.js - submitting a case: start from an example, paste, or upload a file; the case is
// checked before it is sent (its JSON syntax here, then everything a submission checks by the
// server's POST /v1/cases/validate: the case schema and the solver's own loader), and every
// problem is shown at the field it names: the JSON pointer is found in the text (pointer.js),
// its line marked and the message set beside it. Only a case that passes is submitted. The
// case's warnings (values that are valid but most likely not what was meant) are shown the same
// way, in another colour; a case with warnings is submitted once they have been shown for its
// text, at the second press of Submit.
import { get, post, ApiError } from './api.js';
import { h, clear } from './dom.js';
import { locate } from './pointer.js';

const LINE_PX = 18, PAD_PX = 8;

export function render(root) {
  const examples = h('select', { id: 'example' }, h('option', { value: '' }, 'an example…'));
  const file = h('input', { type: 'file', id: 'case-file', accept: '.json,application/json' });
  const editor = h('textarea', { id: 'case-editor', spellcheck: false, wrap: 'off', rows: 28 });
  const gutter = h('div', { class: 'gutter', id: 'gutter' });
  const notes = h('div', { class: 'notes', id: 'notes' });
  const label = h('input', { id: 'job-name', name: 'name', maxLength: 128, placeholder: 'optional' });
  const priority = h('input', { id: 'priority', type: 'number', min: -100, max: 100, value: 0 });
  const threads = h('input', { id: 'threads', type: 'number', min: 1, max: 256, value: 1 });
  const wall = h('input', { id: 'wall-hours', type: 'number', min: 0.01, step: 'any', value: 24 });
  const problems = h('ul', { class: 'problems', id: 'problems' });
  const status = h('p', { id: 'submit-status', class: 'muted' });
  const validateBtn = h('button', { type: 'button', class: 'secondary', id: 'validate' }, 'Check');
  const submitBtn = h('button', { type: 'button', id: 'submit' }, 'Submit');
  root.append(h('h1', {}, 'Submit a case'),
    h('div', { class: 'submit-source' }, h('label', {}, 'Start from ', examples), h('label', {}, 'or upload ', file)),
    h('div', { class: 'editor' }, gutter, h('div', { class: 'editor-text' }, editor, notes)),
    h('div', { class: 'submit-options' }, h('label', {}, 'Label ', label), h('label', {}, 'Priority ', priority),
      h('label', {}, 'Threads ', threads), h('label', {}, 'Wall time, h ', wall)),
    h('div', { class: 'actions' }, validateBtn, submitBtn), status, problems);

  let marks = [];
  function layout() {
    const lines = editor.value.split('\n').length;
    clear(gutter);
    const bad = new Map(marks.map((m) => [m.line, m]));
    for (let n = 1; n <= lines; n++)
      gutter.append(h('div', { class: bad.has(n) ? (bad.get(n).warning ? 'warn' : 'err') : '', title: bad.has(n) ? bad.get(n).message : '' }, String(n)));
    gutter.scrollTop = editor.scrollTop;
    clear(notes);
    for (const m of marks)
      notes.append(h('div', { class: m.warning ? 'field-warning' : 'field-error', dataset: { field: m.field, line: m.line },
        style: `top:${PAD_PX + (m.line - 1) * LINE_PX - editor.scrollTop}px` }, `${m.pointer}: ${m.message}`));
  }
  editor.addEventListener('scroll', () => { gutter.scrollTop = editor.scrollTop; layout(); });
  editor.addEventListener('input', () => { if (marks.length) { marks = []; clear(problems); } layout(); });

  function setText(text) {
    editor.value = text;
    marks = [];
    clear(problems);
    status.textContent = '';
    layout();
  }

  get('/web/examples/index.json').then((list) => {
    for (const ex of list) examples.append(h('option', { value: ex.file }, ex.title));
  }).catch(() => {});
  examples.onchange = async () => {
    if (!examples.value) return;
    file.value = '';   // the editor no longer holds the uploaded file
    const res = await fetch('/web/examples/' + examples.value);
    setText(JSON.stringify(await res.json(), null, 2));
  };
  file.onchange = async () => { if (file.files[0]) { examples.value = ''; setText(await file.files[0].text()); } };

  // Shows the problems: each at its line in the editor (fields of the case), and in the list.
  function showProblems(list, warning = false) {
    marks = [];
    clear(problems);
    problems.className = warning ? 'problems warnings' : 'problems';
    for (const p of list) {
      const inCase = p.field === '/case' || p.field.startsWith('/case/');
      const pointer = inCase ? p.field.slice(5) || '/' : p.field;
      const where = inCase ? locate(editor.value, pointer) : null;
      if (where) marks.push({ field: p.field, pointer, line: where.line, message: p.message, start: where.start, end: where.end, warning });
      problems.append(h('li', { class: warning ? 'warning' : 'problem', dataset: { field: p.field } },
        where ? h('button', { class: 'link', onclick: () => { editor.focus(); editor.setSelectionRange(where.start, where.end); } }, `line ${where.line}`) : 'request',
        ' ', h('code', {}, pointer), ' ', p.message));
    }
    if (marks.length) editor.scrollTop = Math.max(0, (Math.min(...marks.map((m) => m.line)) - 4) * LINE_PX);
    layout();
  }

  function body() {
    let c;
    try {
      c = JSON.parse(editor.value);
    } catch (e) {
      // V8 says "... at position N" (and newer ones "(line L column C)")
      const m = /position (\d+)/.exec(e.message);
      const line = m ? editor.value.slice(0, Number(m[1])).split('\n').length : 1;
      marks = [{ field: '/case', pointer: '/', line, message: e.message }];
      clear(problems).append(h('li', { class: 'problem', dataset: { field: '/case' } }, `line ${line}: not JSON: ${e.message}`));
      layout();
      status.textContent = 'The case is not valid JSON.';
      return null;
    }
    const b = { case: c, priority: Number(priority.value), threads: Number(threads.value),
      wall_time_seconds: Math.round(Number(wall.value) * 3600) };
    if (label.value.trim()) b.name = label.value.trim();
    return b;
  }

  // The body to submit, or null after showing why not: problems, or warnings not yet shown for
  // this text when submitting.
  let warned = null;   // the text whose warnings were last shown
  async function check(submitting) {
    const b = body();
    if (!b) return null;
    status.textContent = 'Checking…';
    try {
      const ok = await post('/v1/cases/validate', b);
      const warnings = ok.warnings || [];
      marks = [];
      clear(problems);
      layout();
      status.textContent = `The case is valid: ${ok.title || '(no title)'}.`;
      if (warnings.length) {
        showProblems(warnings, true);
        const n = warnings.length === 1 ? '1 warning' : `${warnings.length} warnings`;
        if (submitting && warned !== editor.value) {
          warned = editor.value;
          status.textContent = `The case is valid, with ${n}: press Submit again to submit it as it is.`;
          return null;
        }
        warned = editor.value;
        status.textContent = `The case is valid, with ${n}: ${ok.title || '(no title)'}.`;
      }
      return b;
    } catch (e) {
      if (!(e instanceof ApiError)) throw e;
      showProblems(e.problems.length ? e.problems : [{ field: e.field || '', message: e.message }]);
      status.textContent = e.message;
      status.className = 'error';
      return null;
    }
  }

  validateBtn.onclick = () => { status.className = 'muted'; check(false); };
  submitBtn.onclick = async () => {
    status.className = 'muted';
    submitBtn.disabled = true;
    try {
      const b = await check(true);
      if (!b) return;
      const job = await post('/v1/jobs', b);
      location.hash = `#/jobs/${job.id}`;
    } catch (e) {
      status.className = 'error';
      status.textContent = e.message;
    } finally {
      submitBtn.disabled = false;
    }
  };
  layout();
}
