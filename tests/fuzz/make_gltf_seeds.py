#!/usr/bin/env python3
"""Writes the glTF seed corpus (seeds/gltf): small valid files that reach
every feature st_gltf.cpp reads. Run from this folder; the outputs are
committed, so this only needs rerunning when the seeds should change."""
import base64, json, struct

def pad(b, fill):
    return b + fill * (-len(b) % 4)

def glb(doc, binary):
    j = pad(json.dumps(doc, separators=(",", ":")).encode(), b" ")
    b = pad(binary, b"\0")
    body = struct.pack("<II", len(j), 0x4E4F534A) + j + struct.pack("<II", len(b), 0x004E4942) + b
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body

# A unit quad: positions, normals (+z), lightmap UVs, u16 indices.
pos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
nrm = struct.pack("<12f", *([0, 0, 1] * 4))
uv = struct.pack("<8f", 0, 0, 1, 0, 1, 1, 0, 1)
idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
quad_bin = pos + nrm + uv + idx
quad = {
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 683, "color": [1, 0.5, 0.25]}]}},
    "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
    "nodes": [
        {"mesh": 0, "translation": [1, 2, 3], "scale": [2, 2, 2]},
        {"camera": 0, "translation": [0, 1, 5]},
        {"translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"rotation": [0, 0.70710678, 0, 0.70710678], "children": [4]},
        {"mesh": 0, "translation": [1, 0, 0]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1, "zfar": 50}}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1]},
                   "emissiveFactor": [0.5, 0, 0], "doubleSided": True}],
    "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_1": 2},
                                                "indices": 3, "material": 0}]}],
    "buffers": [{"byteLength": len(quad_bin)}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 128},
                    {"buffer": 0, "byteOffset": 128, "byteLength": 12}],
    "accessors": [
        {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 0, "byteOffset": 96, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
}
open("seeds/gltf/quad.glb", "wb").write(glb(quad, quad_bin))

# JSON glTF with an embedded buffer: interleaved positions + u16 normalized
# UVs (byteStride), u8 indices, no normals (flat), a matrix, no "scenes".
inter = b"".join(struct.pack("<3f2H", x, y, 0, u, v) for x, y, u, v in
                 [(0, 0, 0, 0), (1, 0, 65535, 0), (1, 1, 65535, 65535), (0, 1, 0, 65535)])
tri_idx = struct.pack("<6B", 0, 1, 2, 2, 3, 0)
flat_bin = inter + pad(tri_idx, b"\0")
flat = {
    "asset": {"version": "2.0"},
    "nodes": [{"children": [1], "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0.5, 0, 1]},
              {"mesh": 0, "camera": 0}],
    "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
    "materials": [{"emissiveFactor": [1, 1, 1],
                   "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_1": 1}, "indices": 2,
                                "material": 0, "mode": 4}]}],
    "buffers": [{"byteLength": len(flat_bin),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(flat_bin).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(inter), "byteStride": 16},
                    {"buffer": 0, "byteOffset": len(inter), "byteLength": 6}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 0, "byteOffset": 12, "componentType": 5123, "normalized": True, "count": 4, "type": "VEC2"},
        {"bufferView": 1, "componentType": 5121, "count": 6, "type": "SCALAR"}],
}
open("seeds/gltf/flat.gltf", "w").write(json.dumps(flat, indent=1))
open("seeds/gltf/minimal.gltf", "w").write('{"asset": {"version": "2.0"}}\n')
