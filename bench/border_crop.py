#!/usr/bin/python3
"""How far the AO at an image border is from the AO with the image going on
past it: the border handling measured against the estimator itself, not
against Cycles (whose comparison mixes in the estimator's own error).

  bench/border_crop.py OBSCURA OUTDIR [METHOD...]

For each validation scene of $OBSCURA_SHARED_DATA/blender (default
../shared/data), the G-buffer (depth and normals) is cropped to its central
part, an eighth of the width and height off each side, written as an EXR
whose data window is the crop inside the unchanged display window (so the
scene's camera still fits), and `OBSCURA ao` runs on the whole frame and
on the crop at the scene's ao_distance.  Inside the crop the whole frame
has real data beyond the crop's edge; the crop has none.  Per scene and
METHOD (default and gtao unless named; a METHOD is default or an
`--method` value): the MSE and mean of (crop AO - whole frame's AO) over
the crop's pixels with geometry, and both against Cycles on those pixels.
Prints a Markdown table.
"""
import json, os, subprocess, sys
import numpy as np
import OpenImageIO as oiio

CUT = 8  # an eighth of each side off


def channels(path, names):
    b = oiio.ImageBuf(path)
    have = list(b.spec().channelnames)
    px = b.get_pixels(oiio.FLOAT)
    return [px[:, :, have.index(n)].astype(np.float64) for n in names], b.spec()


def crop(src, dst):
    b = oiio.ImageBuf(src)
    s = b.spec()
    names = list(s.channelnames)
    keep = [n for n in names if n.split('.')[-2] in ('Depth', 'Normal')]
    x0, y0 = s.width // CUT, s.height // CUT
    w, h = s.width - 2 * x0, s.height - 2 * y0
    px = b.get_pixels(oiio.FLOAT)[y0:y0 + h, x0:x0 + w, [names.index(n) for n in keep]]
    spec = oiio.ImageSpec(w, h, len(keep), oiio.FLOAT)
    spec.channelnames = keep
    spec.x, spec.y = x0, y0
    spec.full_x, spec.full_y, spec.full_width, spec.full_height = 0, 0, s.width, s.height
    spec.attribute('compression', 'zip')
    out = oiio.ImageOutput.create(dst)
    if not out or not out.open(dst, spec) or not out.write_image(np.ascontiguousarray(px)):
        sys.exit('border_crop: cannot write %s' % dst)
    out.close()


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    obscura, outdir, methods = sys.argv[1], sys.argv[2], sys.argv[3:] or ['default', 'gtao']
    data = os.environ.get('OBSCURA_SHARED_DATA', '../shared/data') + '/blender/validation'
    scenes = sorted(f[:-5] for f in os.listdir(data) if f.endswith('.json') and
                    not f.endswith('.camera.json'))
    os.makedirs(outdir, exist_ok=True)
    print('| scene | method | crop - whole: MSE | mean | vs Cycles: crop | whole |')
    print('|---|---|---|---|---|---|')
    for sc in scenes:
        stem = os.path.join(data, sc)
        with open(stem + '.json') as f:
            dist = json.load(f)['ao_distance']
        cropped = os.path.join(outdir, sc + '.crop_in.exr')
        crop(stem + '.exr', cropped)
        (truth, z), _ = channels(stem + '.exr', ['ViewLayer.AO.R', 'ViewLayer.Depth.Z'])
        for m in methods:
            extra = [] if m == 'default' else ['--method', m]
            ao = {}
            for kind, src in (('whole', stem + '.exr'), ('crop', cropped)):
                out = os.path.join(outdir, '%s.%s.%s.exr' % (sc, m, kind))
                subprocess.run([obscura, 'ao', src, '--camera', stem + '.camera.json', '--radius',
                                str(dist), '--float', '-o', out, '-q'] + extra, check=True)
                (a,), spec = channels(out, ['AO.Y'])
                ao[kind] = (np.clip(a, 0, 1), spec.x, spec.y)
            c, x0, y0 = ao['crop']
            h, w = c.shape
            whole = ao['whole'][0][y0:y0 + h, x0:x0 + w]
            t = np.clip(truth[y0:y0 + h, x0:x0 + w], 0, 1)
            g = z[y0:y0 + h, x0:x0 + w] < 1e9
            d = (c - whole)[g]
            print('| %s | %s | %.6f | %+.5f | %.6f | %.6f |' % (
                sc, m, np.mean(d * d), np.mean(d), np.mean(((c - t)[g]) ** 2),
                np.mean(((whole - t)[g]) ** 2)))
        sys.stdout.flush()


if __name__ == '__main__':
    main()
