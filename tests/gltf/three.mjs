// Loads glTF files with three.js's GLTFLoader (npm `three`, pinned in package-lock.json) under
// node, as a real consumer of EXT_mesh_gpu_instancing, and checks what it builds: each instanced
// node becomes one InstancedMesh per primitive with the node's instance count, and instance i's
// world matrix is the matrix the same scene's --no-gpu-instancing file gives that placement (each
// mesh's placements in node order, instanced or plain, children placed by their parents).
//   node tests/gltf/three.mjs [--expect NAME=COUNT]... INSTANCED NODES [INSTANCED NODES]...
// INSTANCED is a file written with GPU instancing, NODES the same scene with plain nodes.
// Textures: every material three.js built for a glTF material with a baseColorTexture has a map
// whose image holds the bytes of the file's image, and no other material has one. Images are not
// decoded under node (see imageStub below).
// --expect: three.js built an InstancedMesh of COUNT instances for the node named NAME (in every
// INSTANCED file). Exits 1 when a check fails, 2 on bad usage.
import { readGltf, gpuInstancing } from './gltf.mjs';
import { Matrix4, Quaternion, Vector3 } from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

// The one browser global three.js needs under node: FileLoader reports progress while it reads
// a .gltf file's data URI buffer.
globalThis.ProgressEvent ??= class ProgressEvent extends Event {
    constructor(type, init = {}) {
        super(type);
        Object.assign(this, init);
    }
};

// Images under node: three.js's GLTFLoader makes a texture's image with createImageBitmap (and
// reads `self.URL`), which node lacks. This stand-in does not decode the image: it reads its size
// from the PNG or JPEG header and keeps its bytes, which the texture check compares with the file.
globalThis.self ??= globalThis;
globalThis.createImageBitmap ??= async function imageStub(blob) {
    const bytes = new Uint8Array(await blob.arrayBuffer());
    return { ...imageSize(bytes), bytes, close() {} };
};

function imageSize(b) {
    const be = (k, n) => (n === 4 ? ((b[k] << 24) | (b[k + 1] << 16) | (b[k + 2] << 8) | b[k + 3]) >>> 0 : (b[k] << 8) | b[k + 1]);
    if (b[0] === 0x89 && b[1] === 0x50) return { width: be(16, 4), height: be(20, 4) }; // PNG's IHDR
    for (let k = 2; k + 9 < b.length; k += 2 + be(k + 2, 2)) { // JPEG: the first start-of-frame
        const m = b[k + 1];
        if (m >= 0xc0 && m <= 0xcf && m !== 0xc4 && m !== 0xc8 && m !== 0xcc) return { width: be(k + 7, 2), height: be(k + 5, 2) };
    }
    return { width: 0, height: 0 };
}

function sameBytes(a, b) {
    return a !== undefined && a.length === b.length && a.every((x, k) => x === b[k]);
}

// Each three.js material made for a glTF material: a map exactly when that has a baseColorTexture,
// holding the image's bytes. Returns the number of textured materials seen.
function checkTextures(loaded, gltf, problems) {
    const json = gltf.json, parser = loaded.parser;
    let textured = 0;
    const seen = new Set();
    loaded.scene.traverse((o) => {
        for (const material of o.isMesh ? [o.material].flat() : []) {
            const index = parser.associations.get(material)?.materials;
            if (index === undefined || seen.has(material)) continue;
            seen.add(material);
            const want = json.materials[index].pbrMetallicRoughness?.baseColorTexture;
            if (!want !== !material.map) {
                problems.push(`material ${index}: ${material.map ? 'a map without' : 'no map for'} its baseColorTexture`);
                continue;
            }
            if (!want) continue;
            ++textured;
            const view = json.bufferViews[json.images[json.textures[want.index].source].bufferView];
            const start = view.byteOffset ?? 0;
            if (!sameBytes(material.map.image?.bytes, gltf.buffer.subarray(start, start + view.byteLength)))
                problems.push(`material ${index}: its map's image is not the file's image ${want.index}`);
        }
    });
    return textured;
}

function usage() {
    console.error('usage: node tests/gltf/three.mjs [--expect NAME=COUNT]... INSTANCED NODES [INSTANCED NODES]...');
    process.exit(2);
}
const args = process.argv.slice(2);
const expect = new Map(), files = [];
for (let i = 0; i < args.length; ++i) {
    if (args[i] === '--expect' && /^.+=\d+$/.test(args[i + 1] ?? '')) {
        const [name, count] = args[++i].split(/=(?=\d+$)/);
        expect.set(name, Number(count));
    } else if (args[i].startsWith('-')) usage();
    else files.push(args[i]);
}
if (files.length === 0 || files.length % 2 !== 0) usage();

async function load(gltf) {
    const bytes = gltf.bytes;
    const data = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
    return new GLTFLoader().parseAsync(data, '');
}

// The glTF node an object was built for: the nearest one up its parents.
function nodeOf(parser, object) {
    for (let o = object; o; o = o.parent) {
        const nodes = parser.associations.get(o)?.nodes;
        if (nodes !== undefined) return nodes;
    }
    return undefined;
}

// Each node's world matrix (column-major array), composed from the scene's roots down.
function worldMatrices(json) {
    const world = new Map();
    const local = (node) => {
        if (node.matrix) return new Matrix4().fromArray(node.matrix);
        const [tx, ty, tz] = node.translation ?? [0, 0, 0];
        const [qx, qy, qz, qw] = node.rotation ?? [0, 0, 0, 1];
        const [sx, sy, sz] = node.scale ?? [1, 1, 1];
        return new Matrix4().compose(new Vector3(tx, ty, tz), new Quaternion(qx, qy, qz, qw), new Vector3(sx, sy, sz));
    };
    const visit = (n, parent) => {
        const m = local(json.nodes[n]).premultiply(parent);
        world.set(n, m);
        for (const c of json.nodes[n].children ?? []) visit(c, m);
    };
    for (const scene of json.scenes ?? []) for (const n of scene.nodes ?? []) visit(n, new Matrix4());
    return world;
}

// The world matrices of the plain nodes of each mesh, in node order.
function plainMatrices(json) {
    const world = worldMatrices(json);
    const byMesh = new Map();
    for (const [n, node] of (json.nodes ?? []).entries()) {
        if (node.mesh === undefined || node.extensions?.[gpuInstancing]) continue;
        if (!byMesh.has(node.mesh)) byMesh.set(node.mesh, []);
        byMesh.get(node.mesh).push(world.get(n)?.elements ?? new Matrix4().elements);
    }
    return byMesh;
}

function close(a, b) {
    const size = Math.max(1, ...b.map(Math.abs));
    return a.every((x, k) => Math.abs(x - b[k]) <= 1e-4 * size);
}

async function check(instancedFile, nodesFile) {
    const problems = [];
    const instanced = await readGltf(instancedFile), nodes = await readGltf(nodesFile);
    const loaded = await load(instanced);
    loaded.scene.updateMatrixWorld(true);
    const parser = loaded.parser, json = instanced.json;

    // what three.js built, by node
    const built = new Map();
    loaded.scene.traverse((o) => {
        if (!o.isInstancedMesh) return;
        const n = nodeOf(parser, o);
        if (!built.has(n)) built.set(n, []);
        built.get(n).push(o);
    });

    // Every placement of each mesh in the instanced file, in node order: an instanced node's
    // instances as three.js places them, a plain node where its parents put it. They must be the
    // plain nodes of the nodes file, in the same order.
    const expected = plainMatrices(nodes.json);
    const plain = plainMatrices(json);
    const placed = new Map(), plainSeen = new Map();
    const place = (mesh, m) => {
        if (!placed.has(mesh)) placed.set(mesh, []);
        placed.get(mesh).push(m);
    };
    let instancedNodes = 0;
    const counts = new Map();
    for (const [n, node] of (json.nodes ?? []).entries()) {
        if (node.mesh === undefined) continue;
        const ext = node.extensions?.[gpuInstancing];
        if (!ext) {
            const k = plainSeen.get(node.mesh) ?? 0;
            plainSeen.set(node.mesh, k + 1);
            place(node.mesh, plain.get(node.mesh)[k]);
            continue;
        }
        ++instancedNodes;
        const where = `node ${n} (${node.name})`;
        const count = json.accessors[ext.attributes.TRANSLATION].count;
        const meshes = built.get(n) ?? [];
        const primitives = json.meshes[node.mesh].primitives.length;
        if (meshes.length !== primitives)
            problems.push(`${where}: three.js built ${meshes.length} InstancedMeshes for ${primitives} primitives`);
        counts.set(node.name, meshes[0]?.count);
        for (const mesh of meshes)
            if (mesh.count !== count) problems.push(`${where}: InstancedMesh of ${mesh.count}, not ${count}`);
        const m = new Matrix4();
        for (let i = 0; meshes.length > 0 && i < meshes[0].count; ++i) {
            meshes[0].getMatrixAt(i, m);
            place(node.mesh, m.clone().premultiply(meshes[0].matrixWorld).elements);
        }
    }
    for (const [mesh, want] of expected) {
        const got = placed.get(mesh) ?? [];
        if (got.length !== want.length) {
            problems.push(`mesh ${mesh}: ${got.length} placements but ${want.length} plain nodes in ${nodesFile}`);
            continue;
        }
        for (let i = 0; i < want.length; ++i)
            if (!close(got[i], want[i])) {
                problems.push(`mesh ${mesh}: placement ${i} has matrix ${got[i].map((x) => x.toFixed(4))}, ` +
                              `expected ${want[i].map((x) => x.toFixed(4))}`);
                break;
            }
    }
    for (const n of built.keys())
        if (!json.nodes?.[n]?.extensions?.[gpuInstancing]) problems.push(`an InstancedMesh for node ${n}, which is not instanced`);
    for (const [name, count] of expect)
        if (counts.get(name) !== count)
            problems.push(`node '${name}': three.js built ${counts.get(name) ?? 'no'} instances, expected ${count}`);
    const textured = checkTextures(loaded, instanced, problems);
    const total = [...built.values()].reduce((a, list) => a + list.length, 0);
    console.log(`${instancedFile}: three.js built ${total} InstancedMeshes for ${instancedNodes} instanced nodes, ` +
                `${textured} textured materials, ${problems.length} problems`);
    return problems;
}

let failed = false;
for (let k = 0; k < files.length; k += 2) {
    let problems;
    try {
        problems = await check(files[k], files[k + 1]);
    } catch (e) {
        problems = [`cannot load: ${e?.stack ?? e}`];
        console.log(`${files[k]}: failed`);
    }
    for (const p of problems.slice(0, 20)) console.log(`  ${p}`);
    if (problems.length > 0) failed = true;
}
process.exit(failed ? 1 : 0);
