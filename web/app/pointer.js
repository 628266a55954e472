// pointer.js - where a JSON pointer (RFC 6901: "/grid/cell_size", "/bodies/0/porosity") lies in
// the text of a JSON document, so that an error the server names by pointer can be shown at its
// line. A small scanner walks the text (strings with escapes, numbers, literals, nesting) and
// records the position of each value's key, or of the value in an array; locate() answers the
// line (1-based) and the character offsets of the deepest part of the pointer found.

function unescapePointer(token) {
  return token.replace(/~1/g, '/').replace(/~0/g, '~');
}

// Returns {line, start, end, found}: found is the depth of the pointer that exists in the text.
export function locate(text, pointer) {
  const want = pointer.split('/').slice(1).map(unescapePointer);
  let i = 0;
  const ws = () => { while (i < text.length && /\s/.test(text[i])) i++; };
  const str = () => { // at '"': returns the decoded string, i after the closing quote
    let out = '';
    i++;
    while (i < text.length && text[i] !== '"') {
      if (text[i] === '\\') { const n = text[i + 1]; out += n === 'u' ? String.fromCharCode(parseInt(text.substr(i + 2, 4), 16)) : ({ n: '\n', t: '\t', r: '\r', b: '\b', f: '\f' }[n] || n); i += n === 'u' ? 6 : 2; }
      else out += text[i++];
    }
    i++;
    return out;
  };
  let best = { start: 0, end: 0, found: 0 };
  // value at i with path depth d; records a match of want[0..d)
  const value = (d, keyStart) => {
    ws();
    const c = text[i];
    if (c === '{' || c === '[') {
      i++;
      let n = 0;
      for (;;) {
        ws();
        if (text[i] === '}' || text[i] === ']') { i++; break; }
        if (i >= text.length) return;
        let key = String(n), at = i;
        if (c === '{') { key = str(); ws(); i++; /* ':' */ }
        const match = d < want.length && key === want[d] && best.found === d;
        if (match) best = { start: at, end: i, found: d + 1 };
        value(match ? d + 1 : -1, at);
        if (match && best.found === d + 1) best.end = i;
        ws();
        if (text[i] === ',') i++;
        n++;
      }
    } else if (c === '"') str();
    else while (i < text.length && !/[\s,\]}]/.test(text[i])) i++;
  };
  try { value(0, 0); } catch (_) { /* a text that does not parse: the best found so far */ }
  const line = text.slice(0, best.start).split('\n').length;
  return { line, start: best.start, end: best.end, found: best.found, complete: best.found === want.length };
}
