#!/usr/bin/env python3
"""Mitsuba 3 side of bench/compare-mitsuba.sh.

Builds the Mitsuba scene from the exact scene description `NAME.json` in the shared scene
directory (see its README.md for the conventions), renders it with the requested variants and
times the renders; also turns the veach and Mitsuba numbers into the comparison table.

Subcommands (all run inside the bench venv, which has mitsuba and numpy):

  bench   --scenes DIR --scene cbox --scene veach --variants llvm_ad_rgb,scalar_rgb
          --size 256 --spp 64 --depth 8 [--rr-depth 5] [--seed 7] [--repeat 1]
          [--exr-dir DIR] --out FILE.json
  report  --mitsuba FILE.json --veach FILE.json [--json FILE] [--ref-dir DIR]

Scene mapping (JSON -> Mitsuba):
  triangle_mesh       -> binary PLY written to a temp dir, `face_normals: True` (flat shading,
                         normal = normalize(cross(v1-v0, v2-v0)), the same as the JSON)
  diffuse             -> twosided(diffuse)              (the JSON says all surfaces double-sided)
  rough_mirror (ggx)  -> twosided(roughconductor, distribution ggx, alpha, material 'none'
                         = Fresnel 1, specular_reflectance = reflectance, sample_visible true)
  emission area_light -> area emitter (Mitsuba area lights emit from the front face only)
  camera              -> perspective, fov = yfov, fov_axis 'y', look_at(position, target, up)
  environment constant-> constant emitter
  film                -> hdrfilm W x H, box reconstruction filter, rgb
  integrator          -> path, max_depth = --depth, rr_depth = --rr-depth (Mitsuba default 5)
  sampler             -> independent, --spp
"""

import argparse
import json
import os
import platform
import struct
import subprocess
import sys
import tempfile
import time


# ---------------------------------------------------------------------------------------------
# Scene construction


def write_ply(path, vertices, faces):
    """Binary little-endian PLY: float x,y,z per vertex, uchar-count int index lists."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        for v in vertices:
            f.write(struct.pack("<3f", *[float(c) for c in v]))
        for t in faces:
            if len(t) != 3:
                raise ValueError(f"{path}: face {t} is not a triangle")
            f.write(struct.pack("<B3i", 3, *[int(i) for i in t]))


def bsdf_dict(name, mat):
    kind = mat.get("type")
    if kind == "diffuse":
        inner = {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(mat["reflectance"])}}
    elif kind == "rough_mirror":
        dist = mat.get("distribution", "ggx")
        if dist != "ggx":
            raise ValueError(f"material {name}: distribution {dist!r} not supported")
        inner = {
            "type": "roughconductor",
            "distribution": "ggx",
            "alpha": float(mat["alpha"]),
            # 'none' = a perfect conductor: the Fresnel term is exactly 1.
            "material": "none",
            "specular_reflectance": {"type": "rgb", "value": list(mat.get("reflectance", [1, 1, 1]))},
            "sample_visible": True,
        }
    else:
        raise ValueError(f"material {name}: type {kind!r} not supported")
    return {"type": "twosided", "material": inner}


def scene_dict(desc, tmpdir, width, height, spp, depth, rr_depth, seed):
    """A dict for mi.load_dict (the variant must already be set)."""
    import mitsuba as mi

    cam = desc["camera"]
    if cam.get("type", "perspective_pinhole") != "perspective_pinhole":
        raise ValueError(f"camera type {cam.get('type')!r} not supported")
    d = {
        "type": "scene",
        "integrator": {
            "type": "path",
            # veach's 0 = no limit is Mitsuba's -1.
            "max_depth": int(depth) if int(depth) > 0 else -1,
            "rr_depth": int(rr_depth),
            "hide_emitters": False,
        },
        "sensor": {
            "type": "perspective",
            "fov": float(cam["yfov_deg"]),
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["position"], target=cam["target"], up=cam["up"]
            ),
            "sampler": {"type": "independent", "sample_count": int(spp), "seed": int(seed)},
            "film": {
                "type": "hdrfilm",
                "width": int(width),
                "height": int(height),
                "pixel_format": "rgb",
                "component_format": "float32",
                "rfilter": {"type": "box"},
            },
        },
    }
    for name, mat in desc["materials"].items():
        d["bsdf_" + name] = bsdf_dict(name, mat)

    env = desc.get("environment") or {"type": "none"}
    if env.get("type") == "constant":
        d["environment"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(env["radiance"])}}
    elif env.get("type") not in (None, "none"):
        raise ValueError(f"environment type {env.get('type')!r} not supported")

    for i, shape in enumerate(desc["shapes"]):
        if shape.get("type") != "triangle_mesh":
            raise ValueError(f"shape {shape.get('name')}: type {shape.get('type')!r} not supported")
        ply = os.path.join(tmpdir, f"shape{i:03d}.ply")
        write_ply(ply, shape["vertices"], shape["indices"])
        s = {
            "type": "ply",
            "filename": ply,
            "face_normals": True,
            "bsdf": {"type": "ref", "id": "bsdf_" + shape["material"]},
        }
        em = shape.get("emission")
        if em:
            if em.get("type") != "area_light":
                raise ValueError(f"shape {shape.get('name')}: emission {em.get('type')!r} not supported")
            s["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": list(em["radiance"])}}
        d[f"shape{i:03d}_{shape.get('name', '')}"] = s
    return d


def glass_scene_dict(desc, tmpdir, size, spp, depth, rr_depth, seed):
    """assets/cornell-glass.gltf for Mitsuba: the Cornell box of `desc` (cbox.json) plus the
    same triangulated glass sphere (64x32 segments, vertex normals), a dielectric of ior 1.5."""
    import math

    d = scene_dict(desc, tmpdir, size, size, spp, depth, rr_depth, seed)
    cx, cy, cz, r = 278.0, 400.0, 300.0, 100.0
    nu, nv = 64, 32
    pos, nor, idx = [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            nor.append(n)
            pos.append((cx + r * n[0], cy + r * n[1], cz + r * n[2]))
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            b = a + nu + 1
            if j > 0:
                idx.append((a, a + 1, b))
            if j < nv - 1:
                idx.append((a + 1, b + 1, b))
    ply = os.path.join(tmpdir, "sphere.ply")
    with open(ply, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                b"property float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face %d\n"
                b"property list uchar int vertex_indices\nend_header\n" % (len(pos), len(idx)))
        for p, n in zip(pos, nor):
            f.write(struct.pack("<6f", *p, *n))
        for t in idx:
            f.write(struct.pack("<B3i", 3, *t))
    d["glass_sphere"] = {"type": "ply", "filename": ply, "face_normals": False,
                         "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}}
    return d


def load_scene(json_path, width, height, spp, depth, rr_depth, seed):
    import mitsuba as mi

    with open(json_path) as f:
        desc = json.load(f)
    with tempfile.TemporaryDirectory(prefix="veach-mitsuba-") as tmp:
        # The PLY files are read during load_dict, so the temp dir may go afterwards.
        return mi.load_dict(scene_dict(desc, tmp, width, height, spp, depth, rr_depth, seed))


# ---------------------------------------------------------------------------------------------
# Benchmark


def render_once(scene, spp, seed):
    """Wall clock of mi.render plus the conversion to numpy, which forces the JIT variants to
    finish the kernel (and copies the image out, as any use of the image would)."""
    import mitsuba as mi
    import numpy as np

    t0 = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=seed)
    arr = np.array(img)
    return time.perf_counter() - t0, arr


def reference_for(name, max_depth):
    """The shared reference render that fits a scene at a max depth, or None."""
    return {"cbox": {8: "cbox_ref_d8.exr", 0: "cbox_ref.exr"}.get(max_depth),
            "veach": "veach_ref.exr" if max_depth == 2 else None}.get(name)


def convergence_series(scene, spp, seed, reference, until_seconds=0.0):
    """RMSE against `reference` of renders at 1, 2, 4, ... spp, each timed after a warm-up at the
    same spp (the llvm variant compiles a kernel per setting): the error a user gets for the
    time spent, in the same form as veach's --reference series. Goes on doubling past `spp`
    until a render takes `until_seconds` (the other renderer's longest time; at most 16384 spp)."""
    import numpy as np

    series = []
    n = 1
    while True:
        render_once(scene, n, seed)
        secs, img = render_once(scene, n, seed)
        img = img[:, :, :3].astype(np.float64)
        rmse = float(np.sqrt(np.mean((img - reference) ** 2)))
        # As veach's rmse_clamped: the error a tone-mapped image shows.
        clamped = float(np.sqrt(np.mean((np.clip(img, 0, 1) - np.clip(reference, 0, 1)) ** 2)))
        series.append({"spp": n, "seconds": secs, "rmse": rmse, "rmse_clamped": clamped})
        if (n >= spp and secs >= until_seconds) or n >= 16384:
            return series
        n *= 2


def cmd_bench(a):
    import mitsuba as mi
    import numpy as np

    variants = [v for v in a.variants.split(",") if v]
    out = {
        "mitsuba_version": mi.__version__,
        "drjit_version": __import__("drjit").__version__,
        "settings": {
            "width": a.size, "height": a.size, "spp": a.spp, "max_depth": a.depth,
            "rr_depth": a.rr_depth, "seed": a.seed, "repeat": a.repeat,
        },
        "runs": [],
    }
    samples = a.size * a.size * a.spp
    for variant in variants:
        mi.set_variant(variant)
        if variant.startswith("llvm") and "llvm_version" not in out:
            import drjit as dr
            try:
                out["llvm_version"] = ".".join(str(x) for x in dr.detail.llvm_version())
            except Exception:
                out["llvm_version"] = None
        for name in a.scene:
            json_path = os.path.join(a.scenes, name + ".json")
            t0 = time.perf_counter()
            scene = load_scene(json_path, a.size, a.size, a.spp, a.depth, a.rr_depth, a.seed)
            load_s = time.perf_counter() - t0
            # Warm-up at the timed settings: JIT compilation (llvm) and first-touch costs.
            warm_s, _ = render_once(scene, a.spp, a.seed)
            times = []
            img = None
            for _ in range(a.repeat):
                s, img = render_once(scene, a.spp, a.seed)
                times.append(s)
            med = sorted(times)[len(times) // 2]
            mean = [float(x) for x in img.reshape(-1, img.shape[-1])[:, :3].mean(axis=0)]
            rec = {
                "scene": name,
                "renderer": "mitsuba-" + ("llvm" if variant.startswith("llvm") else
                                          "scalar" if variant.startswith("scalar") else variant),
                "variant": variant,
                "seconds_load": load_s,
                "seconds_warmup": warm_s,
                "seconds": med,
                "seconds_all": times,
                "samples_per_second": samples / med,
                "mean_rgb": mean,
            }
            ref_name = reference_for(name, a.depth)
            if a.ref_dir and ref_name and os.path.exists(os.path.join(a.ref_dir, ref_name)):
                ref = read_rgb(os.path.join(a.ref_dir, ref_name))
                if ref.shape[:2] == (a.size, a.size):
                    rec["reference"] = ref_name
                    rec["convergence"] = convergence_series(scene, a.spp, a.seed, ref, a.series_seconds)
            if a.exr_dir:
                os.makedirs(a.exr_dir, exist_ok=True)
                path = os.path.join(a.exr_dir, f"{name}_{rec['renderer']}.exr")
                mi.util.write_bitmap(path, img)
                rec["exr"] = path
            print(
                f"  {name:8s} {variant:12s} warm-up {warm_s:6.2f} s, timed {med:6.2f} s "
                f"({samples / med / 1e6:.2f} Msamples/s), mean {mean[0]:.4f} {mean[1]:.4f} {mean[2]:.4f}",
                file=sys.stderr, flush=True,
            )
            out["runs"].append(rec)
            del scene
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)


# ---------------------------------------------------------------------------------------------
# Report


def read_rgb(path):
    import mitsuba as mi
    import numpy as np

    if not mi.variant():
        mi.set_variant("scalar_rgb")
    arr = np.array(mi.Bitmap(path), dtype=np.float64)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    return arr[:, :, :3]


def machine_info():
    model = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    info = {
        "nproc": os.cpu_count(),
        "cpu_model": model,
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "kernel": platform.release(),
        "python": platform.python_version(),
    }
    try:
        info["nproc"] = int(subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip())
    except Exception:
        pass
    return info


def read_veach_runs(tsv):
    """Lines of scene, renderer, stats JSON, image (EXR or empty); repeated runs of one scene
    and renderer are reduced to the median samples/s."""
    groups = {}
    with open(tsv) as f:
        for line in f:
            if not line.strip():
                continue
            scene, renderer, stats_path, img = (line.rstrip("\n").split("\t") + ["", "", "", ""])[:4]
            with open(stats_path) as g:
                stats = json.load(g)
            groups.setdefault((scene, renderer), []).append((stats, img))
    runs, info = [], {}
    for (scene, renderer), items in groups.items():
        items.sort(key=lambda it: it[0]["samples_per_second"])
        stats, img = items[len(items) // 2]
        rec = {
            "scene": scene,
            "renderer": renderer,
            "backend": stats.get("backend"),
            "adapter": stats.get("adapter"),
            "seconds": stats.get("seconds_render"),
            "samples_per_second": stats["samples_per_second"],
            "samples_per_second_all": [it[0]["samples_per_second"] for it in items],
            "stats": stats,
        }
        if img:
            rec["exr"] = img
        runs.append(rec)
        info.setdefault("adapters", {})[renderer] = stats.get("adapter")
    info["runs"] = runs
    return info


def cmd_report(a):
    import numpy as np

    with open(a.mitsuba) as f:
        mts = json.load(f)
    runs = list(mts["runs"])
    veach = read_veach_runs(a.veach_runs) if a.veach_runs else {"runs": []}
    runs = veach["runs"] + runs

    # Image means (and RMSE against Mitsuba llvm / the shared reference) where EXRs exist.
    for r in runs:
        if r.get("exr") and os.path.exists(r["exr"]) and "mean_rgb" not in r:
            r["mean_rgb"] = [float(x) for x in read_rgb(r["exr"]).reshape(-1, 3).mean(axis=0)]
    s = mts["settings"]
    refs = {}
    if a.ref_dir:
        for r in runs:
            name = r["scene"]
            cand = reference_for(name, s["max_depth"])
            if cand and name not in refs and os.path.exists(os.path.join(a.ref_dir, cand)):
                ref = read_rgb(os.path.join(a.ref_dir, cand))
                if ref.shape[0] == s["height"] and ref.shape[1] == s["width"]:
                    refs[name] = (cand, ref)
    for r in runs:
        if not (r.get("exr") and os.path.exists(r["exr"])):
            continue
        img = read_rgb(r["exr"])
        base = next((m for m in runs if m["scene"] == r["scene"] and m["renderer"] == "mitsuba-llvm"
                     and m.get("exr")), None)
        if base is not None and base is not r:
            r["rmse_vs_mitsuba_llvm"] = float(np.sqrt(np.mean((img - read_rgb(base["exr"])) ** 2)))
        if r["scene"] in refs:
            r["reference"] = refs[r["scene"]][0]
            r["rmse_vs_reference"] = float(np.sqrt(np.mean((img - refs[r["scene"]][1]) ** 2)))

    order = ["veach-gpu", "veach-cpu", "mitsuba-llvm", "mitsuba-scalar"]
    scenes = []
    for r in runs:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    by = {(r["scene"], r["renderer"]): r for r in runs}

    print()
    llvm = f", LLVM {mts['llvm_version']}" if mts.get("llvm_version") else ""
    print(f"Mitsuba {mts['mitsuba_version']} (drjit {mts['drjit_version']}{llvm}); "
          f"{s['width']}x{s['height']}, {s['spp']} spp, max depth {s['max_depth']}, "
          f"Mitsuba rr_depth {s['rr_depth']} (veach: 4, src/params.rs RR_DEPTH); median of {s['repeat']} timed run(s)")
    have_rmse = any("rmse_vs_mitsuba_llvm" in r or "rmse_vs_reference" in r for r in runs)
    hdr = f"{'scene':8s} {'renderer':15s} {'Msamples/s':>10s} {'seconds':>8s}  {'mean R G B':>26s}"
    if have_rmse:
        hdr += f"  {'RMSE vs llvm':>12s} {'RMSE vs ref':>11s}"
    print(hdr)
    print("-" * len(hdr))
    for sc in scenes:
        for rn in order:
            r = by.get((sc, rn))
            if r is None:
                continue
            m = r.get("mean_rgb")
            mean = " ".join(f"{x:8.4f}" for x in m) if m else ""
            line = (f"{sc:8s} {rn:15s} {r['samples_per_second'] / 1e6:10.3f} "
                    f"{r.get('seconds', float('nan')):8.2f}  {mean:>26s}")
            if have_rmse:
                a1 = r.get("rmse_vs_mitsuba_llvm")
                a2 = r.get("rmse_vs_reference")
                line += f"  {a1:12.4f}" if a1 is not None else f"  {'':12s}"
                line += f" {a2:11.4f}" if a2 is not None else ""
            print(line)
    equal_time = report_equal_time(scenes, by, a.series_dir)
    print()
    ratios = []
    print(f"{'scene':8s} {'veach-gpu / mitsuba-llvm':>25s} {'veach-cpu / mitsuba-scalar':>27s}")
    for sc in scenes:
        def ratio(x, y):
            rx, ry = by.get((sc, x)), by.get((sc, y))
            if rx and ry and ry["samples_per_second"] > 0:
                return rx["samples_per_second"] / ry["samples_per_second"]
            return None
        g, c = ratio("veach-gpu", "mitsuba-llvm"), ratio("veach-cpu", "mitsuba-scalar")
        ratios.append({"scene": sc, "veach_gpu_over_mitsuba_llvm": g, "veach_cpu_over_mitsuba_scalar": c})
        fmt = lambda v: f"{v:.3f}" if v is not None else "n/a"
        print(f"{sc:8s} {fmt(g):>25s} {fmt(c):>27s}")

    if a.json:
        doc = {
            "machine": machine_info(),
            "mitsuba_version": mts["mitsuba_version"],
            "drjit_version": mts["drjit_version"],
            "llvm_version": mts.get("llvm_version"),
            "settings": s,
            "veach": {k: v for k, v in veach.items() if k != "runs"},
            "runs": runs,
            "ratios": ratios,
            "equal_time": equal_time,
        }
        with open(a.json, "w") as f:
            json.dump(doc, f, indent=1)
        print(f"\nwrote {a.json}")


def rmse_at(series, t, key="rmse"):
    """RMSE at time t on the log-log line through the series' neighbouring points (None outside)."""
    import math

    pts = sorted((p["seconds"], p[key]) for p in series if p["seconds"] > 0 and p[key] > 0)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if t0 <= t <= t1:
            if t1 == t0:
                return e0
            f = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + f * (math.log(e1) - math.log(e0)))
    return None


def report_equal_time(scenes, by, series_dir):
    """Per scene: every renderer's RMSE at 1 s and when each veach render ended; the
    series are also written as stats-like JSON files for `veach plot-convergence`."""
    order = ["veach-gpu", "veach-cpu", "mitsuba-llvm", "mitsuba-scalar"]
    out = []
    for sc in scenes:
        series = {}
        for rn in order:
            r = by.get((sc, rn))
            conv = r and (r.get("convergence") or (r.get("stats") or {}).get("convergence"))
            if conv:
                series[rn] = conv
        if len(series) < 2:
            continue
        if series_dir:
            for rn, conv in series.items():
                with open(os.path.join(series_dir, f"{sc}_{rn}.series.json"), "w") as f:
                    json.dump({"backend": rn, "scene": sc, "convergence": conv}, f, indent=1)
        # At 1 s and at the end of each veach render; a cell stays empty where a series does
        # not reach that time.
        ends = [max(p["seconds"] for p in conv) for rn, conv in series.items() if rn.startswith("veach")]
        times = sorted({1.0, *ends})
        for t in times:
            row = {"scene": sc, "seconds": t}
            for rn, conv in series.items():
                row[rn] = rmse_at(conv, t)
            out.append(row)
    if out:
        print()
        print("RMSE against the shared reference at equal render time (log-log interpolation between")
        print("the renders at 1, 2, 4, ... spp; lower is better)")
        hdr = f"{'scene':8s} {'seconds':>8s}" + "".join(f" {rn:>15s}" for rn in order)
        hdr += f" {'gpu / llvm':>11s} {'cpu / scalar':>13s}"
        print(hdr)
        print("-" * len(hdr))
        for row in out:
            cells = "".join(f" {row[rn]:15.5f}" if row.get(rn) else f" {'':15s}" for rn in order)
            ratio = lambda x, y: f"{row[x] / row[y]:.2f}" if row.get(x) and row.get(y) else "n/a"
            print(f"{row['scene']:8s} {row['seconds']:8.2f}{cells} {ratio('veach-gpu', 'mitsuba-llvm'):>11s}"
                  f" {ratio('veach-cpu', 'mitsuba-scalar'):>13s}")
    return out


def cmd_equal_time(a):
    """Mitsuba llvm's clamped RMSE at the given render times on the scenes of bench/adaptive.sh,
    one line each: scene, seconds, RMSE (log-log interpolation of a timed 1, 2, 4, ... spp
    series, each render warm)."""
    import mitsuba as mi
    import numpy as np

    mi.set_variant("llvm_ad_rgb")
    times = [float(t) for t in a.times.split()]
    desc_dir = a.scenes
    for name, size, depth, ref in (("cbox", 256, 8, a.cbox_ref), ("glass", 64, 8, a.glass_ref),
                                   ("veach", 256, 2, a.veach_ref)):
        with tempfile.TemporaryDirectory(prefix="veach-mitsuba-") as tmp:
            if name == "glass":
                with open(os.path.join(desc_dir, "cbox.json")) as f:
                    d = glass_scene_dict(json.load(f), tmp, size, 1, depth, a.rr_depth, a.seed)
                scene = mi.load_dict(d)
            else:
                scene = load_scene(os.path.join(desc_dir, name + ".json"), size, size, 1, depth, a.rr_depth, a.seed)
        reference = read_rgb(ref).astype(np.float64)
        series = convergence_series(scene, 1, a.seed, reference, until_seconds=max(times) * 1.05)
        for t in times:
            e = rmse_at(series, t, "rmse_clamped")
            print(f"{name} {t:g} {'nan' if e is None else f'{e:.5f}'}", flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("bench")
    b.add_argument("--scenes", required=True)
    b.add_argument("--scene", action="append", required=True)
    b.add_argument("--variants", default="llvm_ad_rgb,scalar_rgb")
    b.add_argument("--size", type=int, default=256)
    b.add_argument("--spp", type=int, default=64)
    b.add_argument("--depth", type=int, default=8)
    b.add_argument("--rr-depth", type=int, default=5)
    b.add_argument("--seed", type=int, default=7)
    b.add_argument("--repeat", type=int, default=1)
    b.add_argument("--exr-dir")
    b.add_argument("--ref-dir", help="shared scenes dir: record a convergence series against its reference")
    b.add_argument("--series-seconds", type=float, default=0.0, help="extend the series to this render time")
    b.add_argument("--out", required=True)
    r = sub.add_parser("report")
    r.add_argument("--mitsuba", required=True)
    r.add_argument("--veach-runs", help="TSV: scene, renderer, stats JSON, image")
    r.add_argument("--json")
    r.add_argument("--ref-dir")
    r.add_argument("--series-dir", help="write each convergence series here for veach plot-convergence")
    e = sub.add_parser("equal-time")
    e.add_argument("--scenes", required=True, help="the shared scenes (cbox.json, veach.json)")
    e.add_argument("--cbox-ref", required=True)
    e.add_argument("--glass-ref", required=True)
    e.add_argument("--veach-ref", required=True)
    e.add_argument("--times", default="1 4 16")
    e.add_argument("--rr-depth", type=int, default=5)
    e.add_argument("--seed", type=int, default=7)
    a = p.parse_args()
    if a.cmd == "equal-time":
        cmd_equal_time(a)
    elif a.cmd == "bench":
        if a.repeat < 1:
            p.error("--repeat must be >= 1")
        cmd_bench(a)
    else:
        cmd_report(a)


if __name__ == "__main__":
    main()
