#!/usr/bin/python3
"""Where a method's error against Cycles sits, per scene: the share of the
MSE from pixels too light by more than 0.1 (missing occlusion), from
pixels too dark by more than 0.1 (halos, over-occlusion), and the mean
error in a band of 5 % of the width along the image border against the
interior's (border darkening).  Pixels with geometry only.

  bench/error_split.py OUTDIR     OUTDIR/SCENE.exr from `obscura ao` (AO.Y),
                                  for the scenes of ../shared/data/blender
"""
import glob, os, sys
import numpy as np
import OpenImageIO as oiio

def channel(path, name):
    b = oiio.ImageBuf(path)
    names = list(b.spec().channelnames)
    return b.get_pixels(oiio.FLOAT)[:, :, names.index(name)]

data = os.environ.get('OBSCURA_SHARED_DATA', '../shared/data') + '/blender'
scenes = [data + '/room.exr', data + '/yard.exr'] + sorted(
    p for p in glob.glob(data + '/validation/*.exr') if not p.endswith('_eevee_ao.exr'))
print('| scene | MSE | too light > 0.1: pixels, share of MSE | too dark > 0.1: pixels, share of MSE '
      '| mean error, border band / interior |')
print('|---|---|---|---|---|')
for truth in scenes:
    name = os.path.basename(truth)[:-4]
    cand = os.path.join(sys.argv[1], name + '.exr')
    if not os.path.exists(cand):
        continue
    t, z = channel(truth, 'ViewLayer.AO.R'), channel(truth, 'ViewLayer.Depth.Z')
    e = channel(cand, 'AO.Y') - t
    m = (z > 0) & (z < 1e9)
    se = (e[m] ** 2).sum()
    light, dark = m & (e > 0.1), m & (e < -0.1)
    h, w = m.shape
    bw = w // 20
    band = np.zeros_like(m)
    band[:bw, :] = band[-bw:, :] = band[:, :bw] = band[:, -bw:] = True
    print('| %s | %.5f | %.1f %%, %.0f %% | %.1f %%, %.0f %% | %+.4f / %+.4f |' % (
        name, se / m.sum(), 100 * light.sum() / m.sum(), 100 * (e[light] ** 2).sum() / se,
        100 * dark.sum() / m.sum(), 100 * (e[dark] ** 2).sum() / se,
        e[band & m].mean(), e[m & ~band].mean()))
