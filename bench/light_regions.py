"""Error by region of light-sampler renders (bench/light-samplers.sh --regions).

Usage: light_regions.py REFERENCE.exr ALBEDO.exr IMAGE.exr...

Prints, per image, the MSE of values clamped to [0, 4] and the RMSE of values clamped to
[0, 1] against the reference, over the whole image and by region: glossy where the first
surface's albedo AOV (ALBEDO.exr, layer albedo.R/G/B) has luminance above 0.8 (the white
metal plates of the Veach scene and the glossy hall's runner; no diffuse surface of these
scenes is that bright), diffuse elsewhere. Needs numpy and OpenEXR (pip install OpenEXR).
"""
import sys

import numpy as np
import OpenEXR


def channels(path, prefix=""):
    with OpenEXR.File(path, separate_channels=True) as f:
        c = f.channels()
        return np.stack([np.asarray(c[prefix + k].pixels, dtype=np.float64) for k in "RGB"], axis=2)


def errors(img, ref, mask):
    se4 = ((np.clip(img, 0, 4) - np.clip(ref, 0, 4)) ** 2).mean(axis=2)
    se1 = ((np.clip(img, 0, 1) - np.clip(ref, 0, 1)) ** 2).mean(axis=2)
    if not mask.any():
        return float("nan"), float("nan")
    return se4[mask].mean(), np.sqrt(se1[mask].mean())


def main():
    ref = channels(sys.argv[1])
    albedo = channels(sys.argv[2], "albedo.")
    glossy = (albedo @ np.array([0.2126, 0.7152, 0.0722])) > 0.8
    regions = [("image", np.ones_like(glossy)), ("glossy", glossy), ("diffuse", ~glossy)]
    print(f"  regions: glossy {glossy.mean() * 100:.1f} % of pixels")
    for path in sys.argv[3:]:
        parts = []
        for name, mask in regions:
            mse4, rmse1 = errors(channels(path), ref, mask)
            parts.append(f"{name} mse4 {mse4:.6f} rmse1 {rmse1:.5f}")
        print(f"  {path.rsplit('/', 1)[-1]:<22} " + " | ".join(parts))


if __name__ == "__main__":
    main()
