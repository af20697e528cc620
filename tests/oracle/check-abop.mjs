#!/usr/bin/env node
// Independent oracle for `plant derive`.
//
// Every grammar below is re-stated here for lindenmayer.js 1.5.4 (it is NOT read from the .plant
// file), derived with that library, and compared with what `PLANT derive -n N FILE` prints.
// Non-parametric strings are compared module by module; parametric ones are parsed into modules
// and their parameters compared within 1e-9 relative.
//
// Usage:
//   node check-abop.mjs PLANT            compare every case with the plant binary PLANT
//   node check-abop.mjs PLANT NAME...    only the named cases (e.g. fig1_24d fig2_6a)
//   node check-abop.mjs --counts         print each case's lindenmayer.js string length, no plant
//
// Output: one line per case, `ok NAME` or `FAIL NAME: ...`, then `N passed, N failed`.
// Exit status: 0 when nothing failed, 1 otherwise, 2 on bad usage.

import LSystem from 'lindenmayer';
import { spawnSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const grammarsDir = resolve(here, '..', '..', 'grammars');

// ---------------------------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------------------------

// A plain (OL) L-system on strings.
function ol(axiom, productions) {
    return () => new LSystem({ axiom, productions });
}

// lindenmayer.js walks a right context past the ']' that closes the current branch and keeps
// matching in the parent axis. cpfg, L-Py and plant (docs/language.md, productions) do not: a symbol whose axis
// ends (a ']' or the end of the string, after ignored symbols and skipped lateral branches) has
// no right context at all. This guard, used as the production's condition, rejects exactly those
// symbols; for every other symbol lindenmayer.js's own match decides.
function hasRightNeighbour(str, index, ignored) {
    let j = index + 1;
    while (j < str.length) {
        const c = str[j];
        if (ignored.includes(c)) {
            j++;
        } else if (c === '[') {
            let depth = 1;
            j++;
            while (j < str.length && depth > 0) {
                if (str[j] === '[') depth++;
                else if (str[j] === ']') depth--;
                j++;
            }
        } else {
            return c !== ']';
        }
    }
    return false;
}

// ABOP Fig. 1.31: two-state context-sensitive systems (a = ABOP's 0, b = ABOP's 1), ignoring
// + - F, with + and - swapped every step. `table` lists the successors for the left < strict >
// right triples in ABOP's order: aaa aab aba abb baa bab bba bbb.
function hogeweg(axiom, table) {
    const ignored = '+-F';
    const triples = ['aaa', 'aab', 'aba', 'abb', 'baa', 'bab', 'bba', 'bbb'];
    const guard = ({ index, currentAxiom }) => hasRightNeighbour(currentAxiom, index, ignored);
    return () => {
        const productions = {};
        triples.forEach((t, i) => {
            // Classic syntax 'l<s>r'; lindenmayer.js collects every production of one
            // strict symbol in order and applies the first whose context and condition hold.
            productions[`${t[0]}<${t[1]}>${t[2]}`] = { successor: table[i], condition: guard };
        });
        productions['+'] = '-';
        productions['-'] = '+';
        return new LSystem({ axiom, productions, branchSymbols: '[]', ignoredSymbols: ignored });
    };
}

// A module object for parametric systems: {symbol, params}.
const M = (symbol, ...params) => ({ symbol, params });

// ABOP Fig. 2.6: Honda's monopodial tree. d = 137.5, wr = 0.707, axiom A(1,10).
function hondaMonopodial(r1, r2, a0, a2) {
    const d = 137.5;
    const wr = 0.707;
    return () =>
        new LSystem({
            axiom: [M('A', 1, 10)],
            productions: {
                A: ({ part }) => {
                    const [l, w] = part.params;
                    return [M('!', w), M('F', l), M('['), M('&', a0), M('B', l * r2, w * wr), M(']'),
                            M('/', d), M('A', l * r1, w * wr)];
                },
                B: ({ part }) => {
                    const [l, w] = part.params;
                    return [M('!', w), M('F', l), M('['), M('-', a2), M('$'), M('C', l * r2, w * wr), M(']'),
                            M('C', l * r1, w * wr)];
                },
                C: ({ part }) => {
                    const [l, w] = part.params;
                    return [M('!', w), M('F', l), M('['), M('+', a2), M('$'), M('B', l * r2, w * wr), M(']'),
                            M('B', l * r1, w * wr)];
                },
            },
        });
}

// ABOP Fig. 2.7: Honda's sympodial tree. wr = 0.707, axiom A(1,10).
function hondaSympodial(r1, r2, a1, a2) {
    const wr = 0.707;
    return () =>
        new LSystem({
            axiom: [M('A', 1, 10)],
            productions: {
                A: ({ part }) => {
                    const [l, w] = part.params;
                    return [M('!', w), M('F', l), M('['), M('&', a1), M('B', l * r1, w * wr), M(']'),
                            M('/', 180), M('['), M('&', a2), M('B', l * r2, w * wr), M(']')];
                },
                B: ({ part }) => {
                    const [l, w] = part.params;
                    return [M('!', w), M('F', l), M('['), M('+', a1), M('$'), M('B', l * r1, w * wr), M(']'),
                            M('['), M('-', a2), M('$'), M('B', l * r2, w * wr), M(']')];
                },
            },
        });
}

// ---------------------------------------------------------------------------------------------
// The cases: name, grammar file (relative to grammars/), n used here, and the system.
// n is the grammar file's own derivation length unless noted; every string stays well under
// 200k modules (run with --counts to see the lengths).
// ---------------------------------------------------------------------------------------------

const cases = [
    // ABOP Fig. 1.24, bracketed OL-systems
    { name: 'fig1_24a', file: 'abop/fig1_24a.plant', n: 5, make: ol('F', { F: 'F[+F]F[-F]F' }) },
    { name: 'fig1_24b', file: 'abop/fig1_24b.plant', n: 5, make: ol('F', { F: 'F[+F]F[-F][F]' }) },
    { name: 'fig1_24c', file: 'abop/fig1_24c.plant', n: 4, make: ol('F', { F: 'FF-[-F+F+F]+[+F-F-F]' }) },
    { name: 'fig1_24d', file: 'abop/fig1_24d.plant', n: 7, make: ol('X', { X: 'F[+X]F[-X]+X', F: 'FF' }) },
    { name: 'fig1_24e', file: 'abop/fig1_24e.plant', n: 7, make: ol('X', { X: 'F[+X][-X]FX', F: 'FF' }) },
    { name: 'fig1_24f', file: 'abop/fig1_24f.plant', n: 5, make: ol('X', { X: 'F-[[X]+X]+F[+FX]-X', F: 'FF' }) },

    // ABOP sec. 1.2, Koch constructions
    { name: 'koch_island', file: 'abop/koch_island.plant', n: 3, make: ol('F-F-F-F', { F: 'F-F+F+FF-F-F+F' }) },
    { name: 'fig1_7a', file: 'abop/fig1_7a.plant', n: 2,
      make: ol('F-F-F-F', { F: 'F+FF-FF-F-F+F+FF-F-F+F+FF+FF-F' }) },
    { name: 'fig1_7b', file: 'abop/fig1_7b.plant', n: 4, make: ol('-F', { F: 'F+F-F-F+F' }) },
    { name: 'fig1_8', file: 'abop/fig1_8.plant', n: 2,
      make: ol('F+F+F+F', { F: 'F+f-FF+F+FF+Ff+FF-f+FF-F-FF-Ff-FFF', f: 'ffffff' }) },
    { name: 'fig1_9a', file: 'abop/fig1_9a.plant', n: 4, make: ol('F-F-F-F', { F: 'FF-F-F-F-F-F+F' }) },
    { name: 'fig1_9b', file: 'abop/fig1_9b.plant', n: 4, make: ol('F-F-F-F', { F: 'FF-F-F-F-FF' }) },
    { name: 'fig1_9c', file: 'abop/fig1_9c.plant', n: 3, make: ol('F-F-F-F', { F: 'FF-F+F-F-FF' }) },
    { name: 'fig1_9d', file: 'abop/fig1_9d.plant', n: 4, make: ol('F-F-F-F', { F: 'FF-F--F-F' }) },
    { name: 'fig1_9e', file: 'abop/fig1_9e.plant', n: 5, make: ol('F-F-F-F', { F: 'F-FF--F-F' }) },
    { name: 'fig1_9f', file: 'abop/fig1_9f.plant', n: 4, make: ol('F-F-F-F', { F: 'F-F+F-F-F' }) },

    // ABOP Fig. 1.31, context-sensitive (Hogeweg and Hesper)
    { name: 'fig1_31a', file: 'abop/fig1_31a.plant', n: 30,
      make: hogeweg('FbFbFb', ['a', 'b[+FbFb]', 'b', 'b', 'a', 'bFb', 'a', 'a']) },
    { name: 'fig1_31b', file: 'abop/fig1_31b.plant', n: 30,
      make: hogeweg('FbFbFb', ['b', 'b[-FbFb]', 'b', 'b', 'a', 'bFb', 'b', 'a']) },
    { name: 'fig1_31c', file: 'abop/fig1_31c.plant', n: 26,
      make: hogeweg('FbFbFb', ['a', 'b', 'a', 'b[+FbFb]', 'a', 'bFb', 'a', 'a']) },
    { name: 'fig1_31d', file: 'abop/fig1_31d.plant', n: 24,
      make: hogeweg('FaFbFb', ['b', 'a', 'a', 'bFb', 'b', 'b[+FbFb]', 'b', 'a']) },
    { name: 'fig1_31e', file: 'abop/fig1_31e.plant', n: 26,
      make: hogeweg('FbFbFb', ['a', 'b[-FbFb]', 'b', 'b', 'a', 'bFb', 'b', 'a']) },

    // ABOP Fig. 2.6, Honda's monopodial trees (r1, r2, a0, a2)
    { name: 'fig2_6a', file: 'abop/fig2_6a.plant', n: 10, make: hondaMonopodial(0.9, 0.6, 45, 45) },
    { name: 'fig2_6b', file: 'abop/fig2_6b.plant', n: 10, make: hondaMonopodial(0.9, 0.9, 45, 45) },
    { name: 'fig2_6c', file: 'abop/fig2_6c.plant', n: 10, make: hondaMonopodial(0.9, 0.8, 45, 45) },
    { name: 'fig2_6d', file: 'abop/fig2_6d.plant', n: 10, make: hondaMonopodial(0.9, 0.7, 30, -30) },

    // ABOP Fig. 2.7, Honda's sympodial trees (r1, r2, a1, a2)
    { name: 'fig2_7a', file: 'abop/fig2_7a.plant', n: 10, make: hondaSympodial(0.9, 0.7, 5, 65) },
    { name: 'fig2_7b', file: 'abop/fig2_7b.plant', n: 10, make: hondaSympodial(0.9, 0.7, 10, 60) },
    { name: 'fig2_7c', file: 'abop/fig2_7c.plant', n: 10, make: hondaSympodial(0.9, 0.8, 20, 50) },
    { name: 'fig2_7d', file: 'abop/fig2_7d.plant', n: 10, make: hondaSympodial(0.9, 0.8, 35, 35) },

    // L-Py's test_getmod_sons string (grammars/lpy), the one L-Py case lindenmayer.js can state
    { name: 'lpy/getmod_sons', file: 'lpy/getmod_sons.plant', n: 2,
      make: ol('A[+B]B', { A: 'B[+A]A', B: 'A[+B]B' }) },
];

// ---------------------------------------------------------------------------------------------
// Module lists
// ---------------------------------------------------------------------------------------------

// lindenmayer.js result (a string, or an array of {symbol, params}) -> [{name, params}]
function fromLindenmayer(axiom) {
    if (typeof axiom === 'string') return Array.from(axiom, (c) => ({ name: c, params: [] }));
    return axiom.map((m) => ({ name: m.symbol, params: m.params ?? [] }));
}

// Parses `plant derive` output (docs/language.md, printing strings): modules back to back, each an
// @-, ?- or ~-name, a single symbol, or a letter; `multi` lists multi-letter names to read by
// longest match (a space separates such a name from a following letter). Parameters in
// parentheses, separated by commas.
function parsePlant(text, multi = []) {
    const out = [];
    const isIdStart = (c) => /[A-Za-z_]/.test(c);
    const isIdChar = (c) => /[A-Za-z0-9_]/.test(c);
    const names = [...multi].sort((a, b) => b.length - a.length);
    let i = 0;
    while (i < text.length) {
        const c = text[i];
        if (/\s/.test(c)) {
            i++;
            continue;
        }
        let name;
        if ((c === '@' || c === '?' || c === '~') && i + 1 < text.length && isIdStart(text[i + 1])) {
            let j = i + 1;
            while (j < text.length && isIdChar(text[j])) j++;
            name = text.slice(i, j);
        } else if (isIdStart(c)) {
            name = names.find((n) => text.startsWith(n, i)) ?? c;
        } else {
            name = c;
        }
        i += name.length;
        const params = [];
        if (text[i] === '(') {
            const close = text.indexOf(')', i);
            if (close < 0) throw new Error(`unclosed '(' after module ${out.length} '${name}'`);
            for (const field of text.slice(i + 1, close).split(',')) {
                const v = Number(field.trim());
                if (field.trim() === '' || Number.isNaN(v)) {
                    throw new Error(`bad parameter '${field}' of module ${out.length} '${name}'`);
                }
                params.push(v);
            }
            i = close + 1;
        }
        out.push({ name, params });
    }
    return out;
}

function show(m) {
    return m === undefined ? '(end of string)' : m.params.length ? `${m.name}(${m.params.join(',')})` : m.name;
}

function closeEnough(a, b) {
    if (a === b) return true;
    return Math.abs(a - b) <= 1e-9 * Math.max(Math.abs(a), Math.abs(b));
}

function sameModule(x, y) {
    return x !== undefined && y !== undefined && x.name === y.name && x.params.length === y.params.length &&
        x.params.every((v, k) => closeEnough(v, y.params[k]));
}

// Returns null when equal, otherwise a description of the first difference.
function compare(expected, actual) {
    const len = Math.max(expected.length, actual.length);
    for (let k = 0; k < len; k++) {
        if (!sameModule(expected[k], actual[k])) {
            const around = (list) => list.slice(Math.max(0, k - 3), k + 4).map(show).join('');
            return `first difference at module ${k}: expected ${show(expected[k])}, got ${show(actual[k])}` +
                ` (near expected ...${around(expected)}... got ...${around(actual)}...;` +
                ` lengths ${expected.length} expected, ${actual.length} got)`;
        }
    }
    return null;
}

// ---------------------------------------------------------------------------------------------
// Main
// ---------------------------------------------------------------------------------------------

function derive(c) {
    const sys = c.make();
    sys.iterate(c.n);
    return fromLindenmayer(sys.axiom);
}

function main(argv) {
    if (argv[0] === '--counts') {
        for (const c of cases) console.log(`${c.name} n=${c.n}: ${derive(c).length} modules`);
        return 0;
    }
    if (argv.length < 1 || argv[0].startsWith('-')) {
        console.error('usage: check-abop.mjs PLANT [NAME...] | --counts');
        return 2;
    }
    const plant = resolve(argv[0]);
    const only = argv.slice(1);
    const unknown = only.filter((n) => !cases.some((c) => c.name === n));
    if (unknown.length) {
        console.error(`unknown case(s): ${unknown.join(' ')}`);
        return 2;
    }
    let passed = 0;
    let failed = 0;
    for (const c of cases) {
        if (only.length && !only.includes(c.name)) continue;
        const file = join(grammarsDir, c.file);
        let problem = null;
        if (!existsSync(file)) {
            problem = `grammar file ${file} is missing`;
        } else {
            const run = spawnSync(plant, ['derive', '-n', String(c.n), file],
                                  { encoding: 'utf8', maxBuffer: 1 << 28 });
            if (run.error) {
                problem = `could not run ${plant}: ${run.error.message}`;
            } else if (run.status !== 0) {
                const err = (run.stderr || '').trim().split('\n').slice(0, 3).join(' | ');
                problem = `plant exited with ${run.status ?? run.signal}: ${err}`;
            } else {
                try {
                    problem = compare(derive(c), parsePlant(run.stdout));
                } catch (e) {
                    problem = `cannot read plant output: ${e.message}`;
                }
            }
        }
        if (problem) {
            failed++;
            console.log(`FAIL ${c.name}: ${problem}`);
        } else {
            passed++;
            console.log(`ok ${c.name}`);
        }
    }
    console.log(`${passed} passed, ${failed} failed`);
    return failed ? 1 : 0;
}

process.exitCode = main(process.argv.slice(2));
