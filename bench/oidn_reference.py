"""Denoise veach EXRs with the real Intel Open Image Denoise (PyPI pyoidn), for tests/denoise.rs
and BENCHMARKS.md. Run through bench/oidn-reference.sh, which makes the venv.

  strip IN.exr... --out-dir DIR       writes DIR/STEM.input.exr: only the colour, albedo and normal
                                      channels of a veach EXR (compact test inputs)
  reference IN.exr... --out-dir DIR   writes DIR/STEM.CASE.exr for every case below
  bench --size WxH [--repeat N]       times OIDN's CPU device on a synthetic image

Inputs are EXRs written by `veach render --aov albedo,normal` (channels R, G, B, albedo.R/G/B,
normal.X/Y/Z). Cases: balanced and fast with albedo + normal, balanced with albedo only and with
colour only, and balanced with a fixed inputScale of 0.5 (no automatic exposure).
"""
import argparse
import os
import sys
import time

import numpy as np
import OpenEXR
import pyoidn

CASES = [
    # name, quality, albedo, normal, inputScale (None: OIDN measures it)
    ("balanced", pyoidn.OIDN_QUALITY_BALANCED, True, True, None),
    ("fast", pyoidn.OIDN_QUALITY_FAST, True, True, None),
    ("albedo", pyoidn.OIDN_QUALITY_BALANCED, True, False, None),
    ("color", pyoidn.OIDN_QUALITY_BALANCED, False, False, None),
    ("scale05", pyoidn.OIDN_QUALITY_BALANCED, True, True, 0.5),
]


def read_layers(path):
    with OpenEXR.File(path, separate_channels=True) as f:
        ch = {k: v for k, v in f.channels().items()}
        def rgb(names):
            return np.ascontiguousarray(np.stack([ch[n].pixels.astype(np.float32) for n in names], axis=-1))
        color = rgb(["R", "G", "B"])
        albedo = rgb(["albedo.R", "albedo.G", "albedo.B"]) if "albedo.R" in ch else None
        normal = rgb(["normal.X", "normal.Y", "normal.Z"]) if "normal.X" in ch else None
    return color, albedo, normal


def write_rgb(path, img):
    channels = {c: np.ascontiguousarray(img[..., k]) for k, c in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(path)


def denoise(device, color, albedo, normal, quality, scale):
    out = np.zeros_like(color)
    f = pyoidn.Filter(device, pyoidn.OIDN_FILTER_TYPE_RT)
    f.set_image(pyoidn.OIDN_IMAGE_COLOR, color, pyoidn.OIDN_FORMAT_FLOAT3)
    if albedo is not None:
        f.set_image(pyoidn.OIDN_IMAGE_ALBEDO, albedo, pyoidn.OIDN_FORMAT_FLOAT3)
    if normal is not None:
        f.set_image(pyoidn.OIDN_IMAGE_NORMAL, normal, pyoidn.OIDN_FORMAT_FLOAT3)
    f.set_image(pyoidn.OIDN_IMAGE_OUTPUT, out, pyoidn.OIDN_FORMAT_FLOAT3)
    f.set_bool("hdr", True)
    if scale is not None:
        f.set_float("inputScale", scale)
    f.set_quality(quality)
    f.commit()
    f.execute()
    err = device.get_error()
    if err:
        sys.exit(f"OIDN error: {err}")
    f.release()
    return out


def main():
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("strip")
    s.add_argument("inputs", nargs="+")
    s.add_argument("--out-dir", required=True)
    r = sub.add_parser("reference")
    r.add_argument("inputs", nargs="+")
    r.add_argument("--out-dir", required=True)
    b = sub.add_parser("bench")
    b.add_argument("--size", default="512x512")
    b.add_argument("--repeat", type=int, default=3)
    b.add_argument("--quality", default="balanced")
    a = p.parse_args()
    if a.cmd == "strip":
        os.makedirs(a.out_dir, exist_ok=True)
        for path in a.inputs:
            color, albedo, normal = read_layers(path)
            channels = {c: np.ascontiguousarray(color[..., k]) for k, c in enumerate("RGB")}
            channels.update({f"albedo.{c}": np.ascontiguousarray(albedo[..., k]) for k, c in enumerate("RGB")})
            channels.update({f"normal.{c}": np.ascontiguousarray(normal[..., k]) for k, c in enumerate("XYZ")})
            stem = os.path.splitext(os.path.basename(path))[0]
            header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
            with OpenEXR.File(header, channels) as f:
                f.write(os.path.join(a.out_dir, f"{stem}.input.exr"))
        return
    with pyoidn.Device(pyoidn.OIDN_DEVICE_TYPE_CPU) as device:
        device.commit()
        if a.cmd == "reference":
            os.makedirs(a.out_dir, exist_ok=True)
            for path in a.inputs:
                color, albedo, normal = read_layers(path)
                stem = os.path.splitext(os.path.basename(path))[0].removesuffix(".input")
                for name, quality, use_albedo, use_normal, scale in CASES:
                    out = denoise(device, color, albedo if use_albedo else None, normal if use_normal else None,
                                  quality, scale)
                    dst = os.path.join(a.out_dir, f"{stem}.{name}.exr")
                    write_rgb(dst, out)
                    print(f"{dst}: mean {out.mean():.6f}")
        else:
            w, h = (int(v) for v in a.size.split("x"))
            rng = np.random.default_rng(1)
            color = rng.random((h, w, 3), dtype=np.float32) * 2.0
            albedo = rng.random((h, w, 3), dtype=np.float32)
            normal = rng.random((h, w, 3), dtype=np.float32) * 2.0 - 1.0
            quality = {"fast": pyoidn.OIDN_QUALITY_FAST, "balanced": pyoidn.OIDN_QUALITY_BALANCED}[a.quality]
            denoise(device, color, albedo, normal, quality, None)  # warm-up
            times = []
            for _ in range(a.repeat):
                t = time.perf_counter()
                denoise(device, color, albedo, normal, quality, None)
                times.append(time.perf_counter() - t)
            print(f"oidn cpu {a.quality} {w}x{h}: min {min(times):.3f} s, median {sorted(times)[len(times) // 2]:.3f} s")


if __name__ == "__main__":
    main()
