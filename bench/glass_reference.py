# Mitsuba 3 reference for assets/cornell-glass.gltf: the shared cbox.json plus the same
# triangulated glass sphere (64x32 segments, vertex normals), Mitsuba's dielectric, ior 1.5.
# Usage (in the venv bench/compare-mitsuba.sh makes, with DRJIT_LIBLLVM_PATH set as there):
#   python bench/glass_reference.py SIZE SPP SEEDS OUT
# writes OUT.exr (mean of SEEDS renders of SPP samples) and OUT_stderr.exr (per-pixel standard
# error from the spread between seeds). tests/data/cbox_glass_64*.exr: 64 4096 8.
import sys, os, math, json, struct
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba as mi
mi.set_variant('llvm_ad_rgb')
import mitsuba_scenes as ms
import numpy as np

size = int(sys.argv[1]); spp = int(sys.argv[2]); seeds = int(sys.argv[3]); out = sys.argv[4]
desc = json.load(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '../../shared/scenes/cbox.json')))
tmp = os.path.join(os.path.dirname(os.path.abspath(out)) or '.', 'glass-tmp'); os.makedirs(tmp, exist_ok=True)
d = ms.scene_dict(desc, tmp, size, size, spp, 8, 5, 0)
cx, cy, cz, r = 278.0, 400.0, 300.0, 100.0
nu, nv = 64, 32
pos = []; nor = []; idx = []
for j in range(nv + 1):
    th = math.pi * j / nv
    for i in range(nu + 1):
        ph = 2 * math.pi * i / nu
        n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
        nor.append(n); pos.append((cx + r * n[0], cy + r * n[1], cz + r * n[2]))
for j in range(nv):
    for i in range(nu):
        a = j * (nu + 1) + i; b = a + nu + 1
        if j > 0: idx.append((a, a + 1, b))
        if j < nv - 1: idx.append((a + 1, b + 1, b))
ply = os.path.join(tmp, 'sphere.ply')
with open(ply, 'wb') as f:
    f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(pos), len(idx)))
    for p, n in zip(pos, nor):
        f.write(struct.pack('<6f', *p, *n))
    for t in idx:
        f.write(struct.pack('<B3i', 3, *t))
d['glass_sphere'] = {'type': 'ply', 'filename': ply, 'face_normals': False,
                     'bsdf': {'type': 'dielectric', 'int_ior': 1.5, 'ext_ior': 1.0}}
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
