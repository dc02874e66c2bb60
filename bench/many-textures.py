#!/usr/bin/env python3
"""Writes a glTF with textures of many sizes (one 4096², 100 of 256², 60 of 64×48), one quad
each, lit by the sky: the texture-memory benchmark of BENCHMARKS.md (session 11, #17 item 6).
Usage: many-textures.py OUT_DIR (needs numpy and pillow)."""
import base64, io, json, os, struct, sys
import numpy as np
from PIL import Image

out = sys.argv[1]
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(1)
sizes = [(4096, 4096)] + [(256, 256)] * 100 + [(64, 48)] * 60
images, materials, meshes, nodes = [], [], [], []
bin_ = bytearray()
def view(data):
    off = len(bin_); bin_.extend(data); bin_.extend(b"\0" * (-len(bin_) % 4)); return off, len(data)
n = len(sizes); cols = int(np.ceil(np.sqrt(n)))
quad_uv = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
index = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
buffer_views, accessors = [], []
def accessor(data, ctype, count, typ, **kw):
    off, length = view(data)
    buffer_views.append({"buffer": 0, "byteOffset": off, "byteLength": length})
    accessors.append({"bufferView": len(buffer_views) - 1, "componentType": ctype, "count": count, "type": typ, **kw})
    return len(accessors) - 1
uv = accessor(quad_uv, 5126, 4, "VEC2")
idx = accessor(index, 5123, 6, "SCALAR")
for i, (w, h) in enumerate(sizes):
    name = f"tex{i:03d}_{w}x{h}.png"
    # Smooth noise plus a fine checker: detail at every scale, so resampling shows.
    img = (rng.random((h // 8 + 1, w // 8 + 1, 3)) * 255).astype(np.uint8)
    big = np.array(Image.fromarray(img).resize((w, h), Image.BILINEAR))
    y, x = np.mgrid[0:h, 0:w]
    big[((x + y) % 2) == 0] //= 2
    Image.fromarray(big).save(os.path.join(out, name))
    images.append({"uri": name})
    materials.append({"pbrMetallicRoughness": {"baseColorTexture": {"index": i}, "metallicFactor": 0}})
    cx, cy = (i % cols) * 1.1, (i // cols) * 1.1
    pos = struct.pack("<12f", cx, cy, 0, cx + 1, cy, 0, cx + 1, cy + 1, 0, cx, cy + 1, 0)
    p = accessor(pos, 5126, 4, "VEC3", min=[cx, cy, 0], max=[cx + 1, cy + 1, 0])
    meshes.append({"primitives": [{"attributes": {"POSITION": p, "TEXCOORD_0": uv}, "indices": idx, "material": i}]})
    nodes.append({"mesh": i})
c = cols * 1.1 / 2
nodes.append({"camera": 0, "translation": [c, c, 2.2 * c]})
doc = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}],
    "nodes": nodes, "meshes": meshes, "materials": materials, "images": images,
    "textures": [{"source": i} for i in range(n)],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.01}}],
    "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(bin_)).decode(), "byteLength": len(bin_)}],
    "bufferViews": buffer_views, "accessors": accessors,
}
json.dump(doc, open(os.path.join(out, "many-textures.gltf"), "w"))
print(os.path.join(out, "many-textures.gltf"))
