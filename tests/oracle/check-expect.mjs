#!/usr/bin/env node
// Checks the `# expect: STRING` lines of grammar files against `PLANT derive FILE`.
//
// Usage: node check-expect.mjs PLANT [FILE_OR_DIR...]   (default: grammars/lpy)
//
// A file may carry one `# expect:` comment: the string `plant derive` must print for it with the
// file's own derivation length. Whitespace is not significant in the comparison (the grammars
// that use this have only single-letter names). Files without such a line are skipped.
// Output: `ok FILE` / `FAIL FILE: ...` per file, then `N passed, N failed`; exit 1 on failure.

import { spawnSync } from 'node:child_process';
import { readFileSync, readdirSync, statSync } from 'node:fs';
import { dirname, join, relative, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const repo = resolve(here, '..', '..');

function plantFiles(path) {
    if (!statSync(path).isDirectory()) return [path];
    return readdirSync(path).sort().flatMap((e) => plantFiles(join(path, e)))
        .filter((f) => f.endsWith('.plant'));
}

function main(argv) {
    if (argv.length < 1 || argv[0].startsWith('-')) {
        console.error('usage: check-expect.mjs PLANT [FILE_OR_DIR...]');
        return 2;
    }
    const plant = resolve(argv[0]);
    const roots = argv.length > 1 ? argv.slice(1).map((p) => resolve(p)) : [join(repo, 'grammars', 'lpy')];
    let passed = 0;
    let failed = 0;
    for (const file of roots.flatMap(plantFiles)) {
        const line = readFileSync(file, 'utf8').split('\n').find((l) => /^#\s*expect:/.test(l));
        if (!line) continue;
        const name = relative(repo, file);
        const want = line.replace(/^#\s*expect:/, '').replace(/\s+/g, '');
        const run = spawnSync(plant, ['derive', file], { encoding: 'utf8', maxBuffer: 1 << 26 });
        let problem = null;
        if (run.error) {
            problem = `could not run ${plant}: ${run.error.message}`;
        } else if (run.status !== 0) {
            problem = `plant exited with ${run.status ?? run.signal}: ` +
                (run.stderr || '').trim().split('\n').slice(0, 3).join(' | ');
        } else {
            const got = run.stdout.replace(/\s+/g, '');
            if (got !== want) {
                let k = 0;
                while (k < want.length && want[k] === got[k]) k++;
                problem = `expected ${want}, got ${got} (first difference at character ${k})`;
            }
        }
        if (problem) {
            failed++;
            console.log(`FAIL ${name}: ${problem}`);
        } else {
            passed++;
            console.log(`ok ${name}`);
        }
    }
    console.log(`${passed} passed, ${failed} failed`);
    return failed ? 1 : 0;
}

process.exitCode = main(process.argv.slice(2));
