// Textures as plant writes them into glTF (docs/language.md, textures), checked beyond what the
// Khronos validator looks at: each image once, in a buffer view, with the bytes of the file the
// grammar named; one sampler that repeats; textured materials white, untextured ones not textured.
//   node tests/gltf/textures.mjs --image FILE [--textured MESH]... [--plain MESH]... GLTF...
// --image: every image holds exactly FILE's bytes, and there is exactly one.
// --textured MESH: the mesh named MESH has a primitive whose material has a baseColorTexture.
// --plain MESH: the mesh named MESH has a primitive whose material has none (and a colour).
// Exits 1 when a check fails, 2 on bad usage.
import { readFile } from 'node:fs/promises';
import { readGltf } from './gltf.mjs';

function usage() {
    console.error('usage: node tests/gltf/textures.mjs --image FILE [--textured MESH]... [--plain MESH]... GLTF...');
    process.exit(2);
}
const args = process.argv.slice(2);
let imageFile = null;
const textured = [], plain = [], files = [];
for (let i = 0; i < args.length; ++i) {
    const value = () => args[++i] ?? usage();
    if (args[i] === '--image') imageFile = value();
    else if (args[i] === '--textured') textured.push(value());
    else if (args[i] === '--plain') plain.push(value());
    else if (args[i].startsWith('-')) usage();
    else files.push(args[i]);
}
if (!imageFile || files.length === 0) usage();
const image = new Uint8Array(await readFile(imageFile));

const REPEAT = 10497;

function check(gltf) {
    const json = gltf.json, problems = [];
    const images = json.images ?? [], textures = json.textures ?? [], samplers = json.samplers ?? [];
    if (images.length !== 1) problems.push(`${images.length} images, expected 1`);
    if (textures.length !== 1) problems.push(`${textures.length} textures, expected 1`);
    if (samplers.length !== 1) problems.push(`${samplers.length} samplers, expected 1`);
    for (const [k, s] of samplers.entries())
        if ((s.wrapS ?? REPEAT) !== REPEAT || (s.wrapT ?? REPEAT) !== REPEAT) problems.push(`sampler ${k} does not repeat`);
    for (const [k, img] of images.entries()) {
        if (img.uri !== undefined || img.bufferView === undefined) {
            problems.push(`image ${k} is not in a buffer view`);
            continue;
        }
        if (img.mimeType !== 'image/png') problems.push(`image ${k} has mimeType ${img.mimeType}`);
        const view = json.bufferViews[img.bufferView];
        const start = view.byteOffset ?? 0;
        const bytes = gltf.buffer?.subarray(start, start + view.byteLength) ?? new Uint8Array();
        if (bytes.length !== image.length || !bytes.every((x, i) => x === image[i]))
            problems.push(`image ${k} (${bytes.length} bytes) is not ${imageFile} (${image.length} bytes)`);
    }
    const hasTexture = (m) => json.materials[m]?.pbrMetallicRoughness?.baseColorTexture !== undefined;
    for (const [k, m] of (json.materials ?? []).entries()) {
        const pbr = m.pbrMetallicRoughness ?? {};
        if (!hasTexture(k)) continue;
        const t = pbr.baseColorTexture.index;
        if (!(t >= 0 && t < textures.length)) problems.push(`material ${k} names texture ${t}`);
        if (pbr.baseColorFactor && pbr.baseColorFactor.some((x) => x !== 1))
            problems.push(`material ${k} is textured but its baseColorFactor is ${pbr.baseColorFactor}, not white`);
    }
    const meshes = json.meshes ?? [];
    const want = (name, textureWanted) => {
        const mesh = meshes.find((m) => m.name === name);
        if (!mesh) problems.push(`no mesh named '${name}' (meshes: ${meshes.map((m) => m.name).join(', ')})`);
        else if (!mesh.primitives.some((p) => hasTexture(p.material) === textureWanted))
            problems.push(`mesh '${name}' has no ${textureWanted ? 'textured' : 'untextured'} primitive`);
    };
    for (const name of textured) want(name, true);
    for (const name of plain) want(name, false);
    return problems;
}

let failed = false;
for (const file of files) {
    let problems;
    try {
        problems = check(await readGltf(file));
    } catch (e) {
        problems = [`cannot read: ${e}`];
    }
    console.log(`${file}: ${problems.length} problems`);
    for (const p of problems.slice(0, 20)) console.log(`  ${p}`);
    if (problems.length > 0) failed = true;
}
process.exit(failed ? 1 : 0);
