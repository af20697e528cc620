// Checks EXT_mesh_gpu_instancing in glTF files, which the Khronos validator does not: for every
// node carrying it, TRANSLATION (VEC3), ROTATION (VEC4) and SCALE (VEC3) float accessors of one
// count, every value finite, rotations unit quaternions (|q| within 1e-4 of 1), scales positive,
// the node has a mesh, and the extension is listed in extensionsUsed.
//   node tests/gltf/instances.mjs [--require] [--expect NAME=COUNT]... FILE...
// --require: every file has at least one instanced node. --expect: the instanced node named NAME
// has COUNT instances (in every file). Exits 1 when a check fails, 2 on bad usage.
import { readGltf, floatAccessor, gpuInstancing } from './gltf.mjs';

function usage() {
    console.error('usage: node tests/gltf/instances.mjs [--require] [--expect NAME=COUNT]... FILE...');
    process.exit(2);
}
const args = process.argv.slice(2);
let requireSome = false;
const expect = new Map(), files = [];
for (let i = 0; i < args.length; ++i) {
    if (args[i] === '--require') requireSome = true;
    else if (args[i] === '--expect' && /^.+=\d+$/.test(args[i + 1] ?? '')) {
        const [name, count] = args[++i].split(/=(?=\d+$)/);
        expect.set(name, Number(count));
    } else if (args[i].startsWith('-')) usage();
    else files.push(args[i]);
}
if (files.length === 0) usage();

const wanted = { TRANSLATION: 'VEC3', ROTATION: 'VEC4', SCALE: 'VEC3' };

function check(gltf) {
    const problems = [];
    const counts = new Map();
    const used = gltf.json.extensionsUsed ?? [];
    (gltf.json.nodes ?? []).forEach((node, n) => {
        const ext = node.extensions?.[gpuInstancing];
        if (!ext) return;
        const where = `node ${n} (${node.name ?? 'unnamed'})`;
        if (!used.includes(gpuInstancing)) problems.push(`${where}: ${gpuInstancing} is not in extensionsUsed`);
        if (node.mesh === undefined || !gltf.json.meshes?.[node.mesh]) problems.push(`${where}: no mesh`);
        let count = null;
        for (const [name, type] of Object.entries(wanted)) {
            const index = ext.attributes?.[name];
            if (index === undefined) {
                problems.push(`${where}: no ${name} accessor`);
                continue;
            }
            let read;
            try {
                read = floatAccessor(gltf, index);
            } catch (e) {
                problems.push(`${where}: ${name}: ${e.message}`);
                continue;
            }
            if (read.accessor.type !== type) problems.push(`${where}: ${name} is ${read.accessor.type}, not ${type}`);
            if (count === null) count = read.values.length;
            else if (count !== read.values.length)
                problems.push(`${where}: ${name} has ${read.values.length} values, not ${count}`);
            read.values.forEach((v, i) => {
                if (!v.every(Number.isFinite)) problems.push(`${where}: ${name}[${i}] = ${v} is not finite`);
                if (name === 'ROTATION') {
                    const len = Math.hypot(...v);
                    if (!(Math.abs(len - 1) <= 1e-4)) problems.push(`${where}: ROTATION[${i}] has length ${len}`);
                }
                if (name === 'SCALE' && !v.every((s) => s > 0)) problems.push(`${where}: SCALE[${i}] = ${v} is not positive`);
            });
        }
        if (count === 0) problems.push(`${where}: no instances`);
        counts.set(node.name, count);
    });
    return { problems, counts };
}

let failed = false;
for (const file of files) {
    let result;
    try {
        result = check(await readGltf(file));
    } catch (e) {
        console.log(`${file}: cannot check: ${e.message}`);
        failed = true;
        continue;
    }
    const { problems, counts } = result;
    if (requireSome && counts.size === 0) problems.push(`no node carries ${gpuInstancing}`);
    for (const [name, count] of expect)
        if (counts.get(name) !== count)
            problems.push(`instanced node '${name}' has ${counts.get(name) ?? 'no'} instances, expected ${count}`);
    const total = [...counts.values()].reduce((a, b) => a + (b ?? 0), 0);
    console.log(`${file}: ${counts.size} instanced nodes, ${total} instances, ${problems.length} problems`);
    for (const p of problems.slice(0, 20)) console.log(`  ${p}`);
    if (problems.length > 20) console.log(`  ... and ${problems.length - 20} more`);
    if (problems.length > 0) failed = true;
}
process.exit(failed ? 1 : 0);
