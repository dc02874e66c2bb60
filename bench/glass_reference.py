# Mitsuba 3 reference for assets/cornell-glass.gltf: the shared cbox.json plus the same
# triangulated glass sphere (mitsuba_scenes.glass_scene_dict), Mitsuba's dielectric, ior 1.5.
# Usage (in the venv bench/compare-mitsuba.sh makes, with DRJIT_LIBLLVM_PATH set as there):
#   python bench/glass_reference.py SIZE SPP SEEDS OUT
# writes OUT.exr (mean of SEEDS renders of SPP samples) and OUT_stderr.exr (per-pixel standard
# error from the spread between seeds). tests/data/cbox_glass_64*.exr: 64 4096 8.
import sys, os, math, json
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba as mi
mi.set_variant('llvm_ad_rgb')
import mitsuba_scenes as ms
import numpy as np

size = int(sys.argv[1]); spp = int(sys.argv[2]); seeds = int(sys.argv[3]); out = sys.argv[4]
desc = json.load(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '../../shared/scenes/cbox.json')))
tmp = os.path.join(os.path.dirname(os.path.abspath(out)) or '.', 'glass-tmp'); os.makedirs(tmp, exist_ok=True)
d = ms.glass_scene_dict(desc, tmp, size, spp, 8, 5, 0)
imgs = []
for s in range(seeds):
    d['sensor']['sampler']['seed'] = 1000 + s
    scene = mi.load_dict(d)
    imgs.append(np.array(mi.render(scene, spp=spp)))
    print('seed', s, 'mean', imgs[-1].mean(axis=(0, 1)), flush=True)
imgs = np.stack(imgs)
mean = imgs.mean(axis=0)
stderr = imgs.std(axis=0, ddof=1) / math.sqrt(seeds)
mi.Bitmap(mean.astype(np.float32)).write(out + '.exr')
mi.Bitmap(stderr.astype(np.float32)).write(out + '_stderr.exr')
print('image mean', mean.mean(axis=(0, 1)))
