// Reference derivation of ABOP Fig. 1.31a with ABOP/cpfg context rules. Not timed and not
// a competitor: bench/run uses it to check the string plant derives.
//
//   node bench/ref-131a.mjs N      ->  {"n", "symbols", "sha256"}
//
// Why it exists: lindenmayer.js 1.5.4 keeps looking for a right context past the `]` that
// closes the current branch, so for the last symbol of a branch it finds the symbol
// after the branch on the parent axis. In ABOP (and cpfg, L-Py) a branch's last symbol
// has no right context. From step 5 on the two strings differ (n = 20: 604 symbols
// here, 2706 from lindenmayer.js).
//
// Rules used here, with a and b for ABOP's 0 and 1 and "#ignore: +-F":
//   left context: walk left, step over ignored symbols and `[`, jump over a whole
//                 `[...]` branch when meeting its `]`; the first other symbol is it.
//   right context: walk right, step over ignored symbols, jump over a whole `[...]`
//                 branch; meeting `]` (end of the current branch) means none.

import { createHash } from 'node:crypto';

const ignored = new Set(['+', '-', 'F']);
// key: left + strict + right
const table = {
  aaa: 'a', aab: 'b[+FbFb]', aba: 'b', abb: 'b',
  baa: 'a', bab: 'bFb', bba: 'a', bbb: 'a',
};

function rewrite(s) {
  const len = s.length;
  const partner = new Int32Array(len);
  const open = [];
  for (let i = 0; i < len; i++) {
    if (s[i] === '[') open.push(i);
    else if (s[i] === ']') {
      const j = open.pop();
      partner[i] = j;
      partner[j] = i;
    }
  }
  const out = [];
  for (let i = 0; i < len; i++) {
    const c = s[i];
    if (c === '+') { out.push('-'); continue; }
    if (c === '-') { out.push('+'); continue; }
    if (c !== 'a' && c !== 'b') { out.push(c); continue; }
    let left = '';
    for (let j = i - 1; j >= 0; j--) {
      const d = s[j];
      if (ignored.has(d) || d === '[') continue;
      if (d === ']') { j = partner[j]; continue; }
      left = d;
      break;
    }
    let right = '';
    for (let j = i + 1; j < len; j++) {
      const d = s[j];
      if (ignored.has(d)) continue;
      if (d === '[') { j = partner[j]; continue; }
      if (d !== ']') right = d;
      break;
    }
    out.push(table[left + c + right] ?? c);
  }
  return out.join('');
}

const n = Number(process.argv[2]);
if (!Number.isInteger(n) || n < 0) {
  process.stderr.write('usage: node ref-131a.mjs N\n');
  process.exit(2);
}
let word = 'FbFbFb';
for (let k = 0; k < n; k++) word = rewrite(word);
const sha256 = createHash('sha256').update(word).digest('hex');
process.stdout.write(`${JSON.stringify({ n, symbols: word.length, sha256 })}\n`);
