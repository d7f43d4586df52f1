#!/usr/bin/python3
"""How --radius maps to the ray-traced AO distance (bench/QUALITY.md).

Compares the two AO definitions on canonical configurations, numerically:
  ref(D):  occlusion = fraction of cosine-weighted hemisphere rays from p
           that hit geometry within distance D (Cycles' AO pass, 1 - AO.R).
  vao(R):  occlusion = fraction of the volume of the tangent sphere of
           radius R/2 (centre p + n R/2) that lies inside solid geometry
           (VAO, section 3 of the paper, eq 1 without sampling error).
Configurations (solid = a half-space), x the distance to the occluder:
  crease:  p on a floor, a perpendicular wall at horizontal distance x
           (also: p on a wall at height x above the floor; same curves)
  slab:    p on a floor, a parallel solid (ceiling / table top) at height x
and k = R / D is chosen so that both give the same integrated occlusion
over x (the area under the occlusion profile across the crease); the
least-squares k over x is printed for comparison.  Closed forms are
printed beside the Monte-Carlo / quadrature values as a check.  Last,
ao_definition rays (the default): the Monte-Carlo volume fraction at
R = 2D converted as obs__rays_from_volume does (core/chain/vao_cpu.c), beside
the reference, on both configurations.

usage: tools/radius_mapping.py        (deterministic, ~2 s)
"""
import numpy as np

rng = np.random.default_rng(1)
N = 400_000
# cosine-weighted directions (Malley): uniform on the unit disk, lifted
u = rng.random(N); phi = 2 * np.pi * rng.random(N)
dx = np.sqrt(u) * np.cos(phi); dz = np.sqrt(1 - u)
# uniform points in the unit ball (tangent sphere, radius 1 here)
b = rng.normal(size=(N, 3)); b /= np.linalg.norm(b, axis=1)[:, None]
b *= rng.random(N)[:, None] ** (1 / 3)


def ref_occ(cfg, x, D=1.0):
    """fraction of cosine-weighted rays blocked within D."""
    if cfg == "crease":  # wall plane X = x: hit at t = x / dx
        return np.mean(dx * D > x)
    return np.mean(dz * D > x)  # slab plane Z = x: hit at t = x / dz


def vao_occ(cfg, x, R=1.0):
    """fraction of the tangent sphere (radius R/2, centre (0,0,R/2)) in solid."""
    r = R / 2
    if cfg == "crease":
        return np.mean(b[:, 0] * r > x)
    return np.mean(b[:, 2] * r + r > x)


def closed_ref(cfg, a):
    a = np.clip(a, 0, 1)
    if cfg == "crease":  # circular segment of the unit disk beyond a
        return (np.arccos(a) - a * np.sqrt(1 - a * a)) / np.pi
    return 1 - a * a


def closed_vao(cfg, x, R=1.0):
    r = R / 2
    if cfg == "crease":
        h = np.clip(r - x, 0, 2 * r)
    else:
        h = np.clip(2 * r - x, 0, 2 * r)
    return h * h * (3 * r - h) / (4 * r ** 3)


xs = np.linspace(0, 3, 601)  # x in units of D
dxs = xs[1] - xs[0]
print("x/D   crease: ref  vao(R=D)   slab: ref  vao(R=D)   (Monte Carlo; closed form in brackets)")
for x in (0.0, 0.1, 0.25, 0.5, 0.75, 1.0):
    print(f"{x:4.2f}   {ref_occ('crease', x):.4f} [{closed_ref('crease', x):.4f}] "
          f"{vao_occ('crease', x):.4f} [{closed_vao('crease', x):.4f}]   "
          f"{ref_occ('slab', x):.4f} [{closed_ref('slab', x):.4f}] "
          f"{vao_occ('slab', x):.4f} [{closed_vao('slab', x):.4f}]")

ks = np.linspace(0.5, 4.0, 3501)
for cfg in ("crease", "slab"):
    ref = np.array([ref_occ(cfg, x) for x in xs])
    I_ref = np.trapz(ref, dx=dxs)
    # vao(x; R=k) = vao(x/k; R=1): scale the R=1 curve
    vao1 = np.array([vao_occ(cfg, x) for x in xs])
    I_vao1 = np.trapz(vao1, dx=dxs)  # integral for R = 1; scales with R
    k_int = I_ref / I_vao1
    sse = [np.trapz((ref - closed_vao(cfg, xs, k)) ** 2, dx=dxs) for k in ks]
    k_ls = ks[int(np.argmin(sse))]
    sse_int = np.trapz((ref - closed_vao(cfg, xs, k_int)) ** 2, dx=dxs)
    sse_1 = np.trapz((ref - closed_vao(cfg, xs, 1.0)) ** 2, dx=dxs)
    print(f"{cfg}: integral ref = {I_ref:.4f} D, vao = {I_vao1:.4f} R -> "
          f"equal integrated occlusion at k = R/D = {k_int:.4f}; "
          f"least squares over x: k = {k_ls:.3f}; "
          f"squared error k=1: {sse_1:.5f}, k_int: {sse_int:.5f}, k_ls: {min(sse):.5f}")
print(f"closed forms: crease k = 64/(9 pi) = {64 / (9 * np.pi):.4f}; slab k = 4/3 = {4 / 3:.4f}")


def rays_from_volume(o):
    """occlusion o of the sphere of radius D -> of the rays of length D
    (obs__rays_from_volume, in occlusion rather than AO)."""
    o = np.clip(o, 0, 1)
    b = np.clip(2 * np.cos((np.arccos(1 - 2 * np.minimum(o, 0.5)) + np.pi) / 3), 0, 1)
    return np.where(o >= 0.5, o, closed_ref("crease", b))


print("ao_definition rays: R = 2D, converted (Monte Carlo volume), against ref")
print("x/D   crease: ref  rays    slab: ref  rays")
for x in (0.0, 0.1, 0.25, 0.5, 0.75, 1.0, 1.5):
    print(f"{x:4.2f}   {ref_occ('crease', x):.4f} {rays_from_volume(vao_occ('crease', x, 2.0)):.4f}   "
          f"{ref_occ('slab', x):.4f} {rays_from_volume(vao_occ('slab', x, 2.0)):.4f}")
