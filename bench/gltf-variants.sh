#!/usr/bin/env bash
# Makes tests/data/web/: the glTF files web pipelines produce, made by the real tools from
# files the project may redistribute, for tests/gltf_web.rs:
#   gltfpack (npm `gltfpack`, meshoptimizer's packer): quantized geometry (KHR_mesh_quantization,
#     its default) and meshopt compression (EXT_meshopt_compression);
#   glTF-Transform (npm `@gltf-transform/cli`): Draco (KHR_draco_mesh_compression), meshopt, and
#     WebP textures (EXT_texture_webp, through sharp);
#   ktx2-encoder (npm, Basis Universal's encoder in WebAssembly): KHR_texture_basisu, through
#     its glTF-Transform transform (UASTC, required, no fallback), and an ETC1S KTX2 file this
#     script adds to a copy of the textured box beside its PNG (the fallback source).
# Inputs: assets/cornell-box.gltf (veach's own) and BoxTextured from ../shared/models (CC BY 4.0,
# Cesium; attribution in tests/data/README.md). Tools are installed in a temporary folder.
#
#   bench/gltf-variants.sh [OUT_DIR]      (default: tests/data/web)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
out="${1:-$repo/tests/data/web}"
box="$repo/../shared/models/BoxTextured/BoxTextured.gltf"
[ -f "$box" ] || { echo "needs $box (the shared models)"; exit 2; }
mkdir -p "$out"
tools=$(mktemp -d)
trap 'rm -rf "$tools"' EXIT
(cd "$tools" && npm init -y >/dev/null && npm install --silent gltfpack@1.3.0 @gltf-transform/cli@4.5.1 @gltf-transform/core@4.5.1 @gltf-transform/extensions@4.5.1 sharp ktx2-encoder@0.6.0 >/dev/null)
pack="$tools/node_modules/.bin/gltfpack"
gt="$tools/node_modules/.bin/gltf-transform"
cbox="$repo/assets/cornell-box.gltf"
# gltfpack: -noq keeps floats, so the default (quantized) and -cc (meshopt) are the two variants;
# -kn keeps named nodes (the camera), -km keeps materials as they are.
"$pack" -i "$cbox" -o "$out/cornell-box.quantized.glb" -kn -km
"$pack" -i "$cbox" -o "$out/cornell-box.meshopt.glb" -kn -km -cc
"$gt" draco "$cbox" "$out/cornell-box.draco.glb"
"$gt" meshopt "$cbox" "$out/cornell-box.gt-meshopt.glb"
"$pack" -i "$box" -o "$out/box-textured.quantized.glb" -kn -km
"$gt" webp "$box" "$out/box-textured.webp.glb"
# KHR_texture_basisu: the box's PNG as ETC1S in KTX2, beside the PNG as the fallback source.
cp "$box" "$out/box-textured.basisu.gltf"
cp "$(dirname "$box")/BoxTextured0.bin" "$out/"
cp "$(dirname "$box")/CesiumLogoFlat.png" "$out/"
(cd "$tools" && node --input-type=module - "$box" "$out" <<'JS'
import fs from "node:fs";
import path from "node:path";
import sharp from "sharp";
import { encodeToKTX2 } from "ktx2-encoder";
import { ktx2 } from "ktx2-encoder/gltf-transform";
import { NodeIO } from "@gltf-transform/core";
import { ALL_EXTENSIONS } from "@gltf-transform/extensions";
const [box, out] = process.argv.slice(2);
const imageDecoder = async (buffer) => {
  const { data, info } = await sharp(buffer).ensureAlpha().raw().toBuffer({ resolveWithObject: true });
  return { data: new Uint8Array(data), width: info.width, height: info.height };
};
// The PNG as ETC1S in a KTX2 file (for the copy of the box that keeps the PNG as fallback).
const png = fs.readFileSync(path.join(path.dirname(box), "CesiumLogoFlat.png"));
const bytes = await encodeToKTX2(new Uint8Array(png), { isUASTC: false, generateMipmap: false, isSetKTX2SRGBTransferFunc: true, imageDecoder });
fs.writeFileSync(path.join(out, "CesiumLogoFlat.ktx2"), bytes);
// glTF-Transform with ktx2-encoder's transform: UASTC, the extension required, no fallback.
const io = new NodeIO().registerExtensions(ALL_EXTENSIONS);
const doc = await io.read(box);
await doc.transform(ktx2({ isUASTC: true, imageDecoder, generateMipmap: false }));
await io.write(path.join(out, "box-textured.ktx2.glb"), doc);
JS
)
python3 - "$out/box-textured.basisu.gltf" <<'PY'
import json, sys
p = sys.argv[1]
doc = json.load(open(p))
doc["images"].append({"uri": "CesiumLogoFlat.ktx2", "mimeType": "image/ktx2"})
ktx = len(doc["images"]) - 1
for t in doc["textures"]:
    t.setdefault("extensions", {})["KHR_texture_basisu"] = {"source": ktx}
doc.setdefault("extensionsUsed", []).append("KHR_texture_basisu")
json.dump(doc, open(p, "w"), indent=1)
PY
ls -l "$out"
