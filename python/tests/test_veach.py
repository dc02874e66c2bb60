"""The Python package against the command line and its own promises: the same pixels as
the CLI for a seed, AOV shapes and dtypes, the errors, Ctrl-C keeping a partial image and
the GIL released while rendering. Small renders only (CPU engine, <= 64 px)."""

import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import veach

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORNELL = os.path.join(ROOT, "assets", "cornell-box.gltf")


def cli():
    """The release CLI beside the package (CI builds it first and must not skip)."""
    path = os.path.join(ROOT, "target", "release", "veach")
    if not os.path.exists(path):
        if os.environ.get("VEACH_REQUIRE_CLI"):
            pytest.fail(f"{path} is missing (cargo build --release)")
        pytest.skip(f"{path} is missing (cargo build --release)")
    return path


def small(**kw):
    args = dict(width=32, height=24, spp=4, backend="cpu", progress=False)
    args.update(kw)
    return veach.render(CORNELL, **args)


def test_the_render_equals_the_clis_exr_bit_for_bit(tmp_path):
    exr = tmp_path / "cli.exr"
    subprocess.run(
        [cli(), "render", CORNELL, "--width", "32", "--height", "24", "--spp", "4", "--seed", "7",
         "--backend", "cpu", "-o", str(exr)],
        check=True, capture_output=True,
    )
    image = small(seed=7)
    from_cli = veach.read(exr)
    assert image.rgb.dtype == np.float32 and image.rgb.shape == (24, 32, 3)
    assert np.array_equal(image.rgb, from_cli.rgb)
    assert image.rgb.mean() > 0.01
    # The EXR the package writes is the CLI's, byte for byte (pixels, film, job metadata).
    mine = tmp_path / "python.exr"
    image.save(mine)
    assert mine.read_bytes() == exr.read_bytes()


def test_farm_parts_merge_to_the_whole_render(tmp_path):
    parts = []
    for i, r in enumerate(["0..2", "2..4"]):
        p = tmp_path / f"part{i}.exr"
        subprocess.run(
            [cli(), "render", CORNELL, "--width", "32", "--height", "24", "--spp", "4",
             "--sample-range", r, "--backend", "cpu", "-o", str(p)],
            check=True, capture_output=True,
        )
        parts.append(p)
    merged = veach.merge(parts)
    assert merged.spp == 4
    assert np.array_equal(merged.rgb, small().rgb)


def test_the_same_seed_gives_the_same_image_and_another_seed_another():
    a, b, c = small(seed=1), small(seed=1), small(seed=2)
    assert np.array_equal(a.rgb, b.rgb)
    assert not np.array_equal(a.rgb, c.rgb)


def test_aov_shapes_and_dtypes():
    image = small(aovs=("albedo", "normal", "depth"))
    assert image.aov("albedo").shape == (24, 32, 3)
    assert image.aov("normal").shape == (24, 32, 3)
    assert image.aov("depth").shape == (24, 32)
    assert image.aov("variance").shape == (24, 32, 3)
    assert image.aov("spp").shape == (24, 32)
    for name in ["albedo", "normal", "depth", "variance", "spp"]:
        assert image.aov(name).dtype == np.float32, name
    albedo = image.aov("albedo")
    assert 0.0 <= albedo.min() and albedo.max() <= 1.0 and albedo.max() > 0.1
    # The mean of unit normals (misses count zero): at most 1, and 1 inside the box's walls.
    normal_length = np.linalg.norm(image.aov("normal"), axis=2)
    assert normal_length.max() <= 1.0 + 1e-3
    assert np.mean(np.abs(normal_length - 1.0) < 1e-3) > 0.3
    assert np.all(image.aov("spp") == 4)
    # The array is the film's memory handed over once: the same object on every access.
    assert image.rgb is image.rgb
    with pytest.raises(ValueError, match="no AOVs"):
        small().aov("albedo")
    with pytest.raises(ValueError, match="unknown AOV"):
        image.aov("motion")


def test_stats_repr_png_and_save(tmp_path):
    image = small()
    stats = image.stats
    assert stats["spp"] == 4 and stats["width"] == 32 and stats["backend"] == "cpu"
    assert stats["light_sampler"] == "ris" and stats["stopped_by"] == "samples"
    assert stats["samples_per_second"] > 0
    png = image._repr_png_()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    image.save(tmp_path / "a.png")
    assert (tmp_path / "a.png").read_bytes() == png
    with pytest.raises(ValueError, match="unknown output format"):
        image.save(tmp_path / "a.jpg")


def test_scene_info_matches_veach_info():
    scene = veach.load(CORNELL)
    info = scene.info()
    assert info["triangles"] == 32 and info["emissive_triangles"] == 2
    assert info["cameras"] == ["camera"] and info["scene_name"] == "cbox"
    assert info["bounds"][1][1] == pytest.approx(548.8)
    assert "triangles 32" in str(scene)
    # A loaded scene renders as its path does.
    assert np.array_equal(veach.render(scene, width=16, height=16, spp=2, backend="cpu", progress=False).rgb,
                          veach.render(CORNELL, width=16, height=16, spp=2, backend="cpu", progress=False).rgb)


def test_progress_callback_sees_every_sample():
    seen = []
    small(spp=6, progress=lambda done, total, seconds: seen.append((done, total, seconds)))
    assert seen and seen[-1][0] == 6 and all(t == 6 for _, t, _ in seen)
    assert [d for d, _, _ in seen] == sorted(d for d, _, _ in seen)


def test_a_callback_exception_stops_the_render_and_propagates():
    def boom(done, total, seconds):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        small(progress=boom)


def test_denoise():
    image = small(denoise=True)
    assert image.denoised and image.rgb.shape == (24, 32, 3) and np.isfinite(image.rgb).all()
    assert not np.array_equal(image.rgb, image.noisy)
    again = veach.denoise(small(aovs=("albedo", "normal")))
    assert again.denoised and np.isfinite(again.rgb).all()
    with pytest.raises(ValueError, match="denoise quality"):
        veach.denoise(image, quality="best")


def test_errors_are_pythons_with_the_clis_messages(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.gltf"):
        veach.load(tmp_path / "missing.gltf")
    with pytest.raises(FileNotFoundError):
        veach.read(tmp_path / "missing.exr")
    bad = tmp_path / "bad.gltf"
    bad.write_text("{ this is not json")
    with pytest.raises(veach.Error, match="bad.gltf"):
        veach.load(bad)
    not_veach = tmp_path / "plain.exr"
    not_veach.write_bytes(b"\x76\x2f\x31\x01garbage")
    with pytest.raises(veach.Error, match="plain.exr"):
        veach.read(not_veach)
    for kw, pattern in [
        (dict(width=0), "width"),
        (dict(spp=-1), "spp"),
        (dict(width=1.5), "width"),
        (dict(backend="quantum"), "backend"),
        (dict(light_sampler="bogus"), "light sampler"),
        (dict(strategy="guess"), "strategy"),
        (dict(aovs=("motion",)), "AOV"),
        (dict(env=(1, 2)), "three values"),
        (dict(time=-1.0), "time"),
        (dict(width=20000), "image size"),
        (dict(aperture=-1.0), "aperture"),
    ]:
        with pytest.raises(ValueError, match=pattern):
            small(**kw)
    with pytest.raises(FileNotFoundError):
        small(env=str(tmp_path / "sky.hdr"))


CHILD = textwrap.dedent(
    """
    import signal, sys, veach
    # Python ignores Ctrl-C in a process started with SIGINT ignored (a shell's background
    # job): take it back, as an interactive session has it.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    def progress(done, total, seconds):
        if done >= 2:
            print("rendering", flush=True)
    try:
        veach.render(sys.argv[1], width=64, height=64, spp=1000000, backend="cpu", progress=progress)
    except KeyboardInterrupt as e:
        image = e.image
        print("interrupted", image.spp, float(image.rgb.mean()), image.stats["stopped_by"], flush=True)
    """
)


def test_ctrl_c_stops_within_a_second_and_keeps_the_partial_image():
    child = subprocess.Popen([sys.executable, "-c", CHILD, CORNELL], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "rendering"
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        line = child.stdout.readline().split()
        stopped = time.monotonic() - sent
        child.wait(timeout=30)
    finally:
        child.kill()
    assert line[0] == "interrupted", line
    spp, mean, stopped_by = int(line[1]), float(line[2]), line[3]
    assert 2 <= spp < 1000000 and math.isfinite(mean) and mean > 0.01 and stopped_by == "interrupt"
    assert stopped < 1.0, f"took {stopped:.2f} s to stop"


def test_interrupted_is_a_keyboard_interrupt_in_process():
    import _thread

    # interrupt_main does nothing where SIGINT is ignored (pytest run as a background job).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as caught:
            small(width=64, height=64, spp=1000000)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert isinstance(caught.value, veach.Interrupted)
    assert 1 <= caught.value.image.spp < 1000000


def test_the_gil_is_released_while_rendering():
    """Another thread runs while a chunk of samples renders, not only between chunks: its
    ticks (each a 1 ms sleep, which must take the GIL back) fall inside the chunks."""
    chunk_edges = []
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            time.sleep(0.001)
            ticks.append(time.monotonic())

    worker = threading.Thread(target=tick)
    worker.start()
    try:
        small(width=64, height=64, spp=1000000, time=1.5,
              progress=lambda d, t, s: chunk_edges.append(time.monotonic()))
    finally:
        done.set()
        worker.join()
    margin = 0.02
    inside = sum(
        1 for a, b in zip(chunk_edges, chunk_edges[1:]) for t in ticks if a + margin < t < b - margin
    )
    assert len(chunk_edges) >= 3
    assert inside >= 10, f"{inside} ticks of another thread inside {len(chunk_edges) - 1} chunks"
