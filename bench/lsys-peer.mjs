// The lindenmayer.js side of plant's benchmarks.
//
//   node --expose-gc bench/lsys-peer.mjs BENCH N [--reps R] [--hash]
//
// BENCH is one of: abop-1.24d, tree, abop-1.31a.
// Prints one line of JSON:
//   {"bench", "n", "ms", "runs", "symbols", "sha256"?, "lindenmayer"}
// where ms is the best (smallest) of R timed derivations and runs lists all of them.
// Only the iterate() call is timed: node start-up, module loading and building the
// LSystem object are outside the clock. Each repetition builds a fresh LSystem, so it
// derives from the axiom again; later repetitions run on JIT-warm code, which favours
// the peer. With --expose-gc the heap is collected between repetitions (untimed).
//
// bench/run uses it two ways:
//   warm: node --expose-gc lsys-peer.mjs BENCH N --reps R --hash   (one process, best of R)
//   cold: node lsys-peer.mjs BENCH N --reps 1, in R fresh processes: ms is then the
//         process's first and only iterate(), the time a user running a script sees.
//
// --hash adds the SHA-256 of the final string written in ABOP notation (modules back to
// back, parameters in parentheses separated by commas, numbers as JavaScript prints
// them), so the harness can compare it with what `plant derive` prints.

import { createHash } from 'node:crypto';
import { readFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import LSystem from 'lindenmayer';

const here = dirname(fileURLToPath(import.meta.url));
const installed = JSON.parse(
  readFileSync(join(here, 'node_modules', 'lindenmayer', 'package.json'), 'utf8')).version;

// ---- the benchmark grammars, written for lindenmayer.js -------------------------------

// ABOP Fig. 1.24d: plain string rewriting.
function abop124d() {
  return new LSystem({
    axiom: 'X',
    productions: { X: 'F[+X]F[-X]+X', F: 'FF' },
  });
}

// Parametric binary tree. lindenmayer.js has no parametric syntax of its own (its
// classicParametricSyntax is unfinished), so modules are objects {symbol, params} and
// the production is a function, as its README shows for parametric systems.
function tree() {
  const mod = (symbol, params) => (params ? { symbol, params } : { symbol });
  return new LSystem({
    axiom: [mod('A', [1, 10])],
    productions: {
      A: ({ part }) => {
        const [l, w] = part.params;
        return [
          mod('F', [l, w]),
          mod('['), mod('&', [30]), mod('A', [l * 0.9, w * 0.707]), mod(']'),
          mod('/', [137.5]),
          mod('['), mod('&', [-30]), mod('A', [l * 0.7, w * 0.707]), mod(']'),
        ];
      },
    },
  });
}

// ABOP Fig. 1.31a (Hogeweg and Hesper), with a and b standing for ABOP's 0 and 1.
// ABOP gives "#ignore: +-F" for all of Fig. 1.31: F is stepped over when matching
// context, as are + and -. Branches are delimited by [ and ].
function abop131a() {
  return new LSystem({
    axiom: 'FbFbFb',
    branchSymbols: '[]',
    ignoredSymbols: '+-F',
    productions: {
      'a<a>a': 'a',
      'a<a>b': 'b[+FbFb]',
      'a<b>a': 'b',
      'a<b>b': 'b',
      'b<a>a': 'a',
      'b<a>b': 'bFb',
      'b<b>a': 'a',
      'b<b>b': 'a',
      '+': '-',
      '-': '+',
    },
  });
}

const benches = { 'abop-1.24d': abop124d, tree, 'abop-1.31a': abop131a };

// ---- helpers ---------------------------------------------------------------------------

function usage(msg) {
  if (msg) process.stderr.write(`lsys-peer: ${msg}\n`);
  process.stderr.write(
    `usage: node lsys-peer.mjs {${Object.keys(benches).join('|')}} N [--reps R] [--hash]\n`);
  process.exit(2);
}

// The final string in ABOP notation, as plant prints it.
function abopText(word) {
  if (typeof word === 'string') return word;
  let out = '';
  for (const m of word) {
    out += m.symbol;
    if (m.params && m.params.length > 0) out += `(${m.params.join(',')})`;
  }
  return out;
}

// ---- main ------------------------------------------------------------------------------

const args = process.argv.slice(2);
const positional = [];
let reps = 3;
let wantHash = false;
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--reps') reps = Number(args[++i]);
  else if (args[i] === '--hash') wantHash = true;
  else if (args[i].startsWith('--')) usage(`unknown option ${args[i]}`);
  else positional.push(args[i]);
}
if (positional.length !== 2) usage();
const [name, nText] = positional;
const make = benches[name];
if (!make) usage(`unknown benchmark '${name}'`);
const n = Number(nText);
if (!Number.isInteger(n) || n < 0) usage(`bad step count '${nText}'`);
if (!Number.isInteger(reps) || reps < 1) usage('--reps wants a positive integer');

const runs = [];
let word = null;
for (let r = 0; r < reps; r++) {
  word = null;
  if (typeof globalThis.gc === 'function') globalThis.gc();
  const sys = make();
  const t0 = performance.now();
  sys.iterate(n);
  const t1 = performance.now();
  runs.push(t1 - t0);
  word = sys.getRaw();
}

const result = {
  bench: name,
  n,
  ms: Math.min(...runs),
  runs: runs.map((x) => Number(x.toFixed(3))),
  symbols: word.length,
  lindenmayer: installed,
};
if (wantHash) result.sha256 = createHash('sha256').update(abopText(word)).digest('hex');
process.stdout.write(`${JSON.stringify(result)}\n`);
