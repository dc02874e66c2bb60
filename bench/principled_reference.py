#!/usr/bin/env python3
"""Reference values of Mitsuba 3's `principled` BSDF for the lobes it models as glTF does.

With metallic = 1 the principled BSDF is one GGX lobe (anisotropic through Disney's aspect
parameterisation) with Schlick's Fresnel toward the base colour: glTF's metal and
KHR_materials_anisotropy's lobe. This script evaluates Mitsuba's f·cos θ (scalar_rgb, its own
`eval`) on a grid of view and light directions in the local shading frame (x = the tangent
the anisotropy stretches along) and writes them to tests/data/principled.json, which
tests/bsdf.rs compares with veach's `bsdf_eval`.

`principledthin` with eta 1 (no specular reflection) has a Lambertian transmission lobe of
diff_trans / 2 × base colour (Disney's diff_trans runs from 0 to 2): KHR_materials_diffuse_
transmission's lobe with the base colour as its colour. Its values below the surface are the
"diffuse transmission" case (its reflection side is Disney's retro-reflective diffuse, which
glTF does not model).

Run: ~/.cache/veach-bench-venv/bin/python bench/principled_reference.py   (mitsuba 3.9.1, numpy)
"""
import json
import math
import os
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")

BASE = [0.9, 0.6, 0.3]
CASES = [
    {"name": "isotropic metal r=0.5", "roughness": 0.5, "anisotropic": 0.0},
    {"name": "anisotropic metal r=0.5 a=0.8", "roughness": 0.5, "anisotropic": 0.8},
    {"name": "anisotropic metal r=0.3 a=0.5", "roughness": 0.3, "anisotropic": 0.5},
]


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]


def dist_params(roughness, anisotropic):
    """Mitsuba's calc_dist_params (principledhelpers.h): Disney's aspect."""
    r2 = roughness * roughness
    if anisotropic == 0.0:
        a = max(0.001, r2)
        return a, a
    aspect = math.sqrt(1.0 - 0.9 * anisotropic)
    return max(0.001, r2 / aspect), max(0.001, r2 * aspect)


def main():
    out = {
        "origin": "Mitsuba 3 " + mi.__version__ + " principled BSDF, scalar_rgb, bench/principled_reference.py",
        "base_color": BASE,
        "cases": [],
    }
    ctx = mi.BSDFContext()
    for case in CASES:
        props = {
            "type": "principled",
            "base_color": {"type": "rgb", "value": BASE},
            "metallic": 1.0,
            "roughness": case["roughness"],
        }
        if case["anisotropic"] > 0.0:
            props["anisotropic"] = case["anisotropic"]
        bsdf = mi.load_dict(props)
        ax, ay = dist_params(case["roughness"], case["anisotropic"])
        samples = []
        for view_theta in [10.0, 45.0, 75.0]:
            for view_phi in [0.0, 60.0]:
                for light_theta in [5.0, 30.0, 60.0, 80.0]:
                    for light_phi in [0.0, 45.0, 90.0, 135.0, 180.0, 250.0]:
                        view = direction(view_theta, view_phi)
                        light = direction(light_theta, light_phi)
                        si = mi.SurfaceInteraction3f()
                        si.wi = mi.Vector3f(view)
                        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
                        si.sh_frame.s = mi.Vector3f(1, 0, 0)
                        si.sh_frame.t = mi.Vector3f(0, 1, 0)
                        value = bsdf.eval(ctx, si, mi.Vector3f(light))
                        samples.append({"view": view, "light": light, "f_cos": [float(value[i]) for i in range(3)]})
        out["cases"].append({**case, "alpha_x": ax, "alpha_y": ay, "samples": samples})
    # KHR_materials_diffuse_transmission's lobe: principledthin, light below the surface.
    share = 0.4
    thin = mi.load_dict({
        "type": "principledthin",
        "base_color": {"type": "rgb", "value": BASE},
        "diff_trans": 2.0 * share,
        "eta": 1.0,
        "roughness": 0.5,
    })
    samples = []
    for view_theta in [10.0, 45.0, 75.0]:
        for light_theta in [100.0, 120.0, 150.0, 175.0]:
            for light_phi in [0.0, 90.0, 200.0]:
                view = direction(view_theta, 0.0)
                light = direction(light_theta, light_phi)
                si = mi.SurfaceInteraction3f()
                si.wi = mi.Vector3f(view)
                si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
                value = thin.eval(ctx, si, mi.Vector3f(light))
                samples.append({"view": view, "light": light, "f_cos": [float(value[i]) for i in range(3)]})
    out["diffuse_transmission"] = {"share": share, "samples": samples}
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    path = os.path.join(root, "tests", "data", "principled.json")
    with open(path, "w") as f:
        json.dump(out, f, separators=(",", ":"))
    print(f"wrote {path}: {sum(len(c['samples']) for c in out['cases'])} values", file=sys.stderr)


if __name__ == "__main__":
    main()
