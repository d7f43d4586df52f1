#!/usr/bin/python3
"""The error against Cycles split by where it is: per scene and per method,
the MSE of four bands of pixels, each band's share of the pixels and of the
total squared error, EEVEE's beside; and each band's bias (mean signed
error), which tells a halo (too dark) from missed occlusion (too light).

  bench/error_split.py OUTDIR [METHOD...]

OUTDIR/SCENE.METHOD.exr is `obscura ao SCENE.exr --camera SCENE.camera.json
--radius D ... --float` (channel AO.Y) for the scenes of
$OBSCURA_SHARED_DATA/blender (default ../shared/data): room, yard and
validation/*; as bench/quality.sh leaves them in out/quality.  METHOD
defaults to every METHOD found there.  EEVEE is SCENE_eevee_ao.exr
(ViewLayer.AO.R) where the data set has one.  Prints Markdown tables.

Conventions are the referee's (shared/tools/aometrics.py): truth
ViewLayer.AO.R, both images clamped to [0, 1], pixels with geometry only
(ViewLayer.Depth.Z < 1e9); a band's MSE is the mean squared error over its
pixels, its share of the error its squared error over the scene's.

The bands come from each scene's own definitions and nothing else: D is
`ao_distance` of SCENE.json, the camera the projection of SCENE.camera.json
(f_x = P00 W / 2, f_y = P11 H / 2 pixels), z the planar depth
(ViewLayer.Depth.Z), each pixel's view-space position the depth at its
centre pushed through the inverse projection, its normal ViewLayer.Normal
turned into view space by world_to_camera.  r(p) = D f / z(p) is the AO
distance projected to pixels at p's depth.  Each pixel goes to the first
band whose definition it meets:

1. halo: within r(p) of p (a disc, exact: every pixel of it is read)
   lies the near side q of a depth discontinuity, and q is nearer to the
   camera than p by more than D.  q is on the near side of a
   discontinuity when one of its 8 neighbours b is farther from the camera
   and the two are not one surface: b lies more than D behind q's tangent
   plane, or q more than D in front of b's (an open floor seen at a
   grazing angle has steep depth steps but every pixel on its
   neighbours' planes; at a silhouette q's own plane holds the view ray,
   hence the two tests).  q's surface is then more than D from p: it
   cannot block any of p's rays, and whatever occludes p from behind it is
   hidden, so a screen-space estimator guesses (eq 4's range check takes
   it as solid for some distance).  This is the background behind a
   foreground edge.
2. border: p's centre lies within r(p) of the image edge (f_x across the
   width, f_y across the height): part of p's neighbourhood within D is
   off the image.
3. crease/contact: a pixel q within r(p) of p whose surface point lies
   within D of p's (3-D distance), above p's tangent plane and facing p:
   (q - p) . n_p > s |q - p| and (p - q) . n_q > s |q - p|, with
   s = 1 / sqrt(spp), spp the truth's samples per pixel (`samples` of
   SCENE.json, 128).  An occluder seen from p no higher than asin(s)
   above p's tangent plane blocks at most s^2 = 1 / spp of the cosine-
   weighted rays (the share of a cosine lobe within elevation a of the
   plane is sin^2 a): less than one of Cycles' rays, below what the truth
   resolves.  The disc is read on a grid of step max(1, r(p) / 8) pixels
   (every pixel for r(p) <= 8; at most 197 points), so an occluder
   narrower than r(p) / 8 on screen can be missed.
4. open: the rest.
"""
import glob, json, os, sys
import numpy as np
import OpenImageIO as oiio


def channels(path, names):
    b = oiio.ImageBuf(path)
    have = list(b.spec().channelnames)
    px = b.get_pixels(oiio.FLOAT)
    return [px[:, :, have.index(n)].astype(np.float64) for n in names]


def disc_min(z, r):
    """Per pixel, the minimum of z over the pixels whose centres lie within
    r (per pixel, in pixels) of its own: one range-minimum query (sparse
    table along each row) per row of the disc."""
    h, w = z.shape
    table = [z]
    while 2 ** len(table) <= w:
        k = 2 ** (len(table) - 1)
        prev = table[-1]
        nxt = prev.copy()
        nxt[:, :w - k] = np.minimum(prev[:, :w - k], prev[:, k:])
        table.append(nxt)
    log2 = np.zeros(w + 1, dtype=np.int64)
    for n in range(2, w + 1):
        log2[n] = log2[n // 2] + 1
    ys, xs = np.indices(z.shape)
    ys, xs, rr = ys.ravel(), xs.ravel(), r.ravel()
    out = np.full(z.size, np.inf)
    t = np.stack(table)
    for dy in range(-int(rr.max()), int(rr.max()) + 1):
        i = np.nonzero((rr >= abs(dy)) & (ys + dy >= 0) & (ys + dy < h))[0]
        if i.size == 0:
            continue
        half = np.floor(np.sqrt(rr[i] ** 2 - dy * dy)).astype(np.int64)
        a = np.maximum(xs[i] - half, 0)
        b = np.minimum(xs[i] + half, w - 1)
        k = log2[b - a + 1]
        row = ys[i] + dy
        m = np.minimum(t[k, row, a], t[k, row, b - (1 << k) + 1])
        out[i] = np.minimum(out[i], m)
    return out.reshape(z.shape)


def bands(scene):
    """The band of each pixel (0 halo, 1 border, 2 crease, 3 open; -1 sky)."""
    meta = json.load(open(scene + '.json'))
    cam = json.load(open(scene + '.camera.json'))
    d = float(meta['ao_distance'])
    s = 1.0 / np.sqrt(float(meta.get('samples', 128)))
    z, nx, ny, nz = channels(scene + '.exr', ['ViewLayer.Depth.Z', 'ViewLayer.Normal.X',
                                              'ViewLayer.Normal.Y', 'ViewLayer.Normal.Z'])
    h, w = z.shape
    geo = z < 1e9
    p = np.array(cam['projection'])
    fx, fy = p[0, 0] * w / 2, p[1, 1] * h / 2
    zz = np.where(geo, z, 1e10)
    r = d * fy / zz  # pixels (square pixels: fx == fy on these cameras)
    rx = d * fx / zz
    ys, xs = np.indices(z.shape)
    # view-space position: camera looks down -Z; Blender's rows run top down
    ndx = 2 * (xs + 0.5) / w - 1
    ndy = 1 - 2 * (ys + 0.5) / h
    pos = np.stack([(ndx + p[0, 2]) * zz / p[0, 0], (ndy + p[1, 2]) * zz / p[1, 1], -zz], -1)
    rot = np.array(cam['world_to_camera'])[:3, :3]
    nrm = np.stack([nx, ny, nz], -1) @ rot.T

    # the near side of a depth discontinuity: a pixel q with an 8-neighbour
    # b farther from the camera such that the two are not one surface: b
    # lies more than D behind q's tangent plane, or q more than D in front
    # of b's (either: at a silhouette q's plane holds the view ray)
    edge = np.zeros_like(geo)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dx or dy:
                by = np.clip(ys + dy, 0, h - 1)
                bx = np.clip(xs + dx, 0, w - 1)
                dv = pos[by, bx] - pos
                edge |= (geo & (zz[by, bx] > zz)
                         & (((dv * nrm).sum(-1) < -d) | (-(dv * nrm[by, bx]).sum(-1) > d)))
    near = np.where(edge, zz, np.inf)
    halo = geo & (disc_min(near, np.where(geo, r, 0)) < zz - d)
    border = geo & ((xs + 0.5 < rx) | (w - xs - 0.5 < rx) | (ys + 0.5 < r) | (h - ys - 0.5 < r))

    crease = np.zeros_like(geo)
    step = np.maximum(1.0, r / 8)
    for v in range(-8, 9):
        for u in range(-8, 9):
            if (u or v) and u * u + v * v <= 64:
                qx = np.rint(xs + u * step).astype(np.int64)
                qy = np.rint(ys + v * step).astype(np.int64)
                ok = geo & (qx >= 0) & (qx < w) & (qy >= 0) & (qy < h) & ~crease
                qx, qy = np.where(ok, qx, 0), np.where(ok, qy, 0)
                ok &= geo[qy, qx]
                dv = pos[qy, qx] - pos
                dist = np.sqrt((dv * dv).sum(-1))
                crease |= (ok & (dist < d) & ((dv * nrm).sum(-1) > s * dist)
                           & (-(dv * nrm[qy, qx]).sum(-1) > s * dist))
    band = np.full(z.shape, -1)
    band[geo] = 3
    band[crease] = 2
    band[border] = 1
    band[halo] = 0
    return band, d


NAMES = ['halo', 'border', 'crease', 'open']


def split(truth, cand, band):
    """Per band: (pixel share, MSE, share of the squared error, bias); and
    the MSE.  The bias is the band's mean signed error, candidate minus
    truth: > 0 too light (occlusion missed), < 0 too dark (a halo)."""
    d = np.clip(cand, 0, 1) - np.clip(truth, 0, 1)
    e = d ** 2
    m = band >= 0
    total = e[m].sum()
    rows = []
    for k in range(4):
        b = band == k
        n = b.sum()
        nan = float('nan')
        rows.append((n / m.sum(), e[b].mean() if n else nan, e[b].sum() / total,
                     d[b].mean() if n else nan))
    return rows, total / m.sum()


def main():
    outdir = sys.argv[1]
    data = os.environ.get('OBSCURA_SHARED_DATA', '../shared/data') + '/blender'
    scenes = [data + '/room', data + '/yard'] + sorted(
        p[:-4] for p in glob.glob(data + '/validation/*.exr') if not p.endswith('_eevee_ao.exr'))
    methods = sys.argv[2:] or sorted({os.path.basename(p).split('.')[1]
                                      for p in glob.glob(outdir + '/*.*.exr')} - {'ref'})
    res = {}  # (scene, method) -> (rows, mse); method 'EEVEE'
    shares, dist = {}, {}
    for s in scenes:
        n = os.path.basename(s)
        if not os.path.exists(s + '.exr'):
            continue
        print('error_split: %s' % n, file=sys.stderr)
        band, dist[n] = bands(s)
        (truth,) = channels(s + '.exr', ['ViewLayer.AO.R'])
        shares[n] = [(band == k).sum() / (band >= 0).sum() for k in range(4)]
        if os.path.exists(s + '_eevee_ao.exr'):
            res[n, 'EEVEE'] = split(truth, channels(s + '_eevee_ao.exr', ['ViewLayer.AO.R'])[0], band)
        for m in methods:
            c = '%s/%s.%s.exr' % (outdir, n, m)
            if os.path.exists(c):
                res[n, m] = split(truth, channels(c, ['AO.Y'])[0], band)

    print('#### The bands: share of each scene\'s pixels with geometry\n')
    print('| scene | AO distance | ' + ' | '.join(NAMES) + ' |')
    print('|---|---|' + '---|' * 4)
    for n in shares:
        print('| %s | %g m | %s |' % (n, dist[n], ' | '.join('%.1f %%' % (100 * x) for x in shares[n])))
    print()
    for m in ['EEVEE'] + list(methods):
        if not any((n, m) in res for n in shares):
            continue
        print('#### %s, by band\n' % m)
        if m == 'EEVEE':
            print('Each band: MSE (share of the scene\'s squared error).\n')
        else:
            print('Each band: MSE (share of the scene\'s squared error), and its MSE over EEVEE\'s in the same band.\n')
        print('| scene | MSE | ' + ' | '.join(NAMES) + ' | largest share |')
        print('|---|---|' + '---|' * 5)
        for n in shares:
            if (n, m) not in res:
                continue
            rows, mse = res[n, m]
            ev = res.get((n, 'EEVEE'))
            cells = []
            for k, (_, bm, sh, _) in enumerate(rows):
                if bm != bm:
                    cells.append('-')
                    continue
                c = '%.5f (%.0f %%)' % (bm, 100 * sh)
                if ev and m != 'EEVEE' and ev[0][k][1] > 0:
                    c += ' %.2f x' % (bm / ev[0][k][1])
                cells.append(c)
            top = max(range(4), key=lambda k: rows[k][2])
            print('| %s | %.5f | %s | %s |' % (n, mse, ' | '.join(cells), NAMES[top]))
        print()
    # the sign of each band's error: a halo (too dark) and missed
    # occlusion (too light) both raise a band's MSE, and a change that
    # removes one adds to the other
    print('#### Bias by band\n')
    print('Each band\'s mean signed error against Cycles (candidate minus truth):'
          ' > 0 too light, < 0 too dark.\n')
    print('| scene | method | ' + ' | '.join(NAMES) + ' |')
    print('|---|---|' + '---|' * 4)
    for n in shares:
        for m in ['EEVEE'] + list(methods):
            if (n, m) in res:
                print('| %s | %s | %s |' % (n, m, ' | '.join(
                    '-' if r[3] != r[3] else '%+.3f' % r[3] for r in res[n, m][0])))
    print()


main()
