// signin.js - the sign-in page: a token pasted into a password field is checked against the API and
// kept in session storage (it ends with the browser tab); the field is emptied at once, so the
// token stays out of the page.
import { token, tryToken } from './api.js';
import { h } from './dom.js';
import { identify } from './main.js';

export function render(root, { onSignedIn }) {
  const input = h('input', { type: 'password', id: 'token', autocomplete: 'off', placeholder: 'poro_…',
                             spellcheck: false, required: true });
  const message = h('p', { class: 'error', id: 'signin-error' });
  const form = h('form', { class: 'card signin', id: 'signin', onsubmit: async (ev) => {
    ev.preventDefault();
    const t = input.value.trim();
    input.value = '';
    message.textContent = '';
    try {
      const status = await tryToken(t);
      if (status) {
        message.textContent = status === 401 ? 'This token is not valid (unknown or revoked).' :
          status === 403 ? 'This token may not use the jobs API (a worker token?).' : `Cannot sign in: HTTP ${status}`;
        return;
      }
      token.set(t);
      await identify();
      onSignedIn();
    } catch (e) {
      token.clear();
      message.textContent = `Cannot sign in: ${e.message}`;
    }
  } },
  h('h1', {}, 'Sign in'),
  h('p', { class: 'muted' }, 'Paste your token (from ', h('code', {}, 'poro-server token create'),
    ' or your administrator). It is kept in this tab only.'),
  h('label', { for: 'token' }, 'Token'), input,
  h('button', { type: 'submit', id: 'signin-button' }, 'Sign in'), message);
  root.append(form);
  input.focus();
}
