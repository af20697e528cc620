// Validates glTF files with the Khronos glTF validator (the pinned npm package in
// tests/gltf/node_modules; install it with tests/gltf/run or `npm ci` in this folder).
//   node tests/gltf/validate.mjs [--verbose] FILE...
// Prints one line per file: its error, warning, info and hint counts; below a file with errors,
// its errors (with --verbose, every issue). Exits 1 when any file has errors or cannot be read,
// 2 on bad usage.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const severities = ['error', 'warning', 'info', 'hint'];
const maxShown = 20;

const args = process.argv.slice(2);
const verbose = args.includes('--verbose') || args.includes('-v');
const files = args.filter((a) => a !== '--verbose' && a !== '-v');
if (files.length === 0 || files.some((f) => f.startsWith('-'))) {
    console.error('usage: node tests/gltf/validate.mjs [--verbose] FILE...');
    process.exit(2);
}

async function validate(file) {
    const bytes = new Uint8Array(await readFile(file));
    return validator.validateBytes(bytes, {
        uri: file,
        maxIssues: 0,
        writeTimestamp: false,
        externalResourceFunction: async (uri) =>
            new Uint8Array(await readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)))),
    });
}

let failed = false;
for (const file of files) {
    let report;
    try {
        report = await validate(file);
    } catch (e) {
        console.log(`${file}: cannot validate: ${e}`);
        failed = true;
        continue;
    }
    const issues = report.issues;
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                `${issues.numInfos} infos, ${issues.numHints} hints`);
    if (issues.numErrors > 0) failed = true;
    const shown = issues.messages.filter((m) => verbose || m.severity === 0);
    for (const m of shown.slice(0, verbose ? shown.length : maxShown)) {
        console.log(`  ${severities[m.severity] ?? m.severity} ${m.code} at ${m.pointer ?? '?'}: ${m.message}`);
    }
    if (!verbose && shown.length > maxShown) console.log(`  ... and ${shown.length - maxShown} more errors`);
}
process.exit(failed ? 1 : 0);
