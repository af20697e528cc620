// Reading the glTF files plant writes, for the checks in this folder: a .glb's JSON and binary
// chunks, or a .gltf with its buffer as a data URI, and float accessors as arrays of tuples.
import { readFile } from 'node:fs/promises';

const components = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 };

// { json, buffer (Uint8Array or null), bytes (the file) }
export async function readGltf(file) {
    const bytes = new Uint8Array(await readFile(file));
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    if (bytes.length >= 12 && view.getUint32(0, true) === 0x46546c67) { // 'glTF'
        let offset = 12, json = null, buffer = null;
        while (offset + 8 <= bytes.length) {
            const length = view.getUint32(offset, true), type = view.getUint32(offset + 4, true);
            const chunk = bytes.subarray(offset + 8, offset + 8 + length);
            if (type === 0x4e4f534a) json = JSON.parse(new TextDecoder().decode(chunk)); // JSON
            else if (type === 0x004e4942) buffer = chunk; // BIN
            offset += 8 + length;
        }
        if (!json) throw new Error('no JSON chunk');
        return { json, buffer, bytes };
    }
    const json = JSON.parse(new TextDecoder().decode(bytes));
    let buffer = null;
    const uri = json.buffers?.[0]?.uri;
    if (uri) {
        const comma = uri.indexOf(',');
        if (!uri.startsWith('data:') || comma < 0) throw new Error('only data URIs are read');
        buffer = new Uint8Array(Buffer.from(uri.slice(comma + 1), 'base64'));
    }
    return { json, buffer, bytes };
}

// The accessor's values, each an array of its components; only float accessors.
export function floatAccessor(gltf, index) {
    const accessor = gltf.json.accessors?.[index];
    if (!accessor) throw new Error(`accessor ${index} does not exist`);
    if (accessor.componentType !== 5126) throw new Error(`accessor ${index} is not FLOAT`);
    const n = components[accessor.type];
    if (!n) throw new Error(`accessor ${index} has type ${accessor.type}`);
    const bufferView = gltf.json.bufferViews[accessor.bufferView];
    const stride = bufferView.byteStride ?? n * 4;
    const start = (bufferView.byteOffset ?? 0) + (accessor.byteOffset ?? 0);
    const end = start + stride * (accessor.count - 1) + n * 4;
    if (accessor.count > 0 && (!gltf.buffer || end > gltf.buffer.length ||
                               end > (bufferView.byteOffset ?? 0) + bufferView.byteLength))
        throw new Error(`accessor ${index} reaches past its buffer view`);
    const view = new DataView(gltf.buffer?.buffer ?? new ArrayBuffer(0), gltf.buffer?.byteOffset ?? 0);
    const values = [];
    for (let i = 0; i < accessor.count; ++i) {
        const tuple = [];
        for (let k = 0; k < n; ++k) tuple.push(view.getFloat32(start + i * stride + k * 4, true));
        values.push(tuple);
    }
    return { accessor, values };
}

export const gpuInstancing = 'EXT_mesh_gpu_instancing';
