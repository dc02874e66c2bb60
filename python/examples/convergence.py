"""Render a glTF with veach, plot its error against a reference as samples and seconds grow
and, where Mitsuba 3 is installed and the scene has a Mitsuba description (the shared
reference scenes: NAME.json beside NAME.gltf), render it with Mitsuba too and compare the two
side by side at equal time.

    pip install ./python matplotlib        # from the repository root
    python python/examples/convergence.py                       # the bundled Cornell box
    python python/examples/convergence.py ../shared/scenes/cbox.gltf \
        --reference ../shared/scenes/cbox_ref_d8.exr --size 256  # against Mitsuba's reference

Writes convergence.png (RMSE against spp and against seconds, log-log) and, with Mitsuba,
side_by_side.png, in --out (default: the current directory).
"""

import argparse
import os
import sys

import numpy as np

import veach

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def rmse(image, reference):
    """The error a tone-mapped image shows: both clamped to [0, 1]."""
    return float(np.sqrt(np.mean((np.clip(image, 0, 1) - np.clip(reference, 0, 1)) ** 2)))


def veach_series(scene, size, max_depth, reference, largest):
    series = []
    spp = 1
    while spp <= largest:
        image = veach.render(scene, width=size, height=size, spp=spp, max_depth=max_depth, seed=7, progress=False)
        series.append((spp, image.stats["seconds_render"], rmse(image.rgb, reference), image))
        spp *= 2
    return series


def mitsuba_series(json_path, size, max_depth, reference, largest, until):
    """Mitsuba's llvm variant over the same scene description, or None without Mitsuba; it
    goes on doubling the spp past `largest` until a render takes `until` seconds."""
    if not os.path.exists(json_path):
        print(f"{json_path} is missing: Mitsuba needs the scene's exact description; veach alone")
        return None
    # Dr.Jit loads libLLVM when imported; LLVM 15 (Debian 12's) aborts on Mitsuba's path
    # integrator, so the llvm variant runs only with LLVM >= 17 (else the scalar variant).
    llvm = os.environ.get("DRJIT_LIBLLVM_PATH") or newest_llvm(17)
    if llvm:
        os.environ["DRJIT_LIBLLVM_PATH"] = llvm
    try:
        import mitsuba as mi
    except ImportError:
        print("Mitsuba 3 is not installed (pip install mitsuba): veach alone")
        return None
    variant = "llvm_ad_rgb" if llvm else "scalar_rgb"
    mi.set_variant(variant)
    print(f"Mitsuba {mi.__version__}, {variant}" + (f" (LLVM {llvm})" if llvm else " (no libLLVM >= 17 found)"))
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    from mitsuba_scenes import load_scene, render_once  # the benchmark's scene mapping

    scene = load_scene(json_path, size, size, 1, max_depth, 3, 7)
    series = []
    spp = 1
    while True:
        render_once(scene, spp, 7)  # the llvm variant compiles a kernel per setting
        seconds, image = render_once(scene, spp, 7)
        series.append((spp, seconds, rmse(image[:, :, :3], reference), image[:, :, :3]))
        if seconds >= until or spp >= 16384:
            break
        spp *= 2
    return series


def newest_llvm(least):
    """The newest libLLVM of at least this major version in the usual places, or None."""
    import glob
    import re

    best, best_major = None, 0
    for path in glob.glob("/usr/lib/*-linux-gnu/libLLVM*") + glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so*"):
        m = re.match(r"libLLVM[-.]?(?:so\.)?(\d+)", os.path.basename(path))
        if m and int(m.group(1)) > best_major:
            best, best_major = path, int(m.group(1))
    return best if best_major >= least else None


def error_at(series, seconds):
    """RMSE at a render time, interpolated in log-log between the renders around it."""
    t = np.log([s[1] for s in series])
    e = np.log([s[2] for s in series])
    return float(np.exp(np.interp(np.log(seconds), t, e)))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", default=os.path.join(ROOT, "assets", "cornell-box.gltf"))
    parser.add_argument("--reference", help="reference EXR of the same size (default: veach at 16x the largest spp)")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--max-depth", type=int, default=8)
    parser.add_argument("--largest", type=int, default=64, help="largest spp of the series")
    parser.add_argument("--out", default=".")
    a = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scene = veach.load(a.scene)
    print(scene)
    if a.reference:
        reference = veach.read_rgb(a.reference)
    else:
        print(f"rendering a reference with veach ({16 * a.largest} spp)")
        reference = veach.render(scene, width=a.size, height=a.size, spp=16 * a.largest, max_depth=a.max_depth,
                                 seed=1234).rgb
    if reference.shape[:2] != (a.size, a.size):
        sys.exit(f"the reference is {reference.shape[1]}x{reference.shape[0]}, the render {a.size}x{a.size}")

    ours = veach_series(scene, a.size, a.max_depth, reference, a.largest)
    theirs = mitsuba_series(os.path.splitext(a.scene)[0] + ".json", a.size, a.max_depth, reference, a.largest,
                            ours[-1][1])

    fig, (by_spp, by_time) = plt.subplots(1, 2, figsize=(10, 4))
    for name, series in [("veach", ours), ("Mitsuba 3", theirs)]:
        if series:
            by_spp.loglog([s[0] for s in series], [s[2] for s in series], "o-", label=name)
            by_time.loglog([s[1] for s in series], [s[2] for s in series], "o-", label=name)
    by_spp.set(xlabel="samples per pixel", ylabel="RMSE (clamped to [0, 1])")
    by_time.set(xlabel="render seconds", ylabel="RMSE (clamped to [0, 1])")
    for ax in (by_spp, by_time):
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "convergence.png"), dpi=120)
    print(f"wrote {os.path.join(a.out, 'convergence.png')}")
    for spp, seconds, error, _ in ours:
        print(f"veach {spp:5d} spp  {seconds:7.3f} s  RMSE {error:.4f}")

    if theirs:
        # Equal time: veach's last render against Mitsuba's error at the same time.
        spp, seconds, error, image = ours[-1]
        other = error_at(theirs, seconds)
        print(f"at {seconds:.2f} s: veach RMSE {error:.4f}, Mitsuba {other:.4f} ({error / other:.2f}x)")
        closest = min(theirs, key=lambda s: abs(np.log(s[1] / seconds)))
        fig, axes = plt.subplots(1, 2, figsize=(10, 5))
        for ax, (title, img) in zip(axes, [(f"veach, {seconds:.2f} s, RMSE {error:.4f}", image.rgb),
                                           (f"Mitsuba 3, {closest[1]:.2f} s, RMSE {closest[2]:.4f}", closest[3])]):
            ax.imshow(np.clip(img, 0, 1) ** (1 / 2.2))
            ax.set_title(title)
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "side_by_side.png"), dpi=120)
        print(f"wrote {os.path.join(a.out, 'side_by_side.png')}")


if __name__ == "__main__":
    main()
