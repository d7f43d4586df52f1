/* Method gtao on deep input with intervals (deep_intervals on, facing
 * flags known): each slice's visibility from its set of free angles
 * instead of one horizon per side.  The CPU twin of gtao.glsl's
 * GT_INTERVALS branch.
 *
 * GTAO's slice visibility (methods/gtao.c; Jimenez et al. 2016, Algorithm
 * 1, the inner integral) is the cosine-weighted measure of the visible
 * directions of the slice,
 *   A_slice / |n_p| = Int_visible cos(theta - gamma) |sin theta| dtheta,
 * theta the angle from v in the slice plane, with the antiderivative
 * a(h) = (cos gamma + 2 h sin gamma - cos(2 h - gamma)) / 4 (a(0) = 0,
 * Int_0^h for h > 0, Int_h^0 for h < 0).  The horizon form takes the
 * visible set of a side as [0, h]: every sample is solid behind it, so
 * everything below the highest one is blocked.  With a node's interval
 * known (its front face at depth w and its matching back face at depth e
 * along the pixel's ray, obs__deep_intervals) the solid it puts in the
 * slice is the segment from q to q + (e - w) dir, which the slice sees
 * as the arc between the angles of its two ends (the angle from v is
 * monotonic along a ray that does not pass through the centre): occupied,
 * the idea of Therrien et al. 2023 ("Screen Space Indirect Lighting with
 * Visibility Bitmask"), but with exact arcs and each occluder's thickness
 * taken from its back face (no thickness constant).
 *
 * The steps sample the slice at a few columns (their pixels' rays), and
 * a surface between two columns blocks rays there too: a wall seen face
 * on from the floor shows each column only a sliver of its thickness.
 * The horizon form covers this by taking each sample solid behind (the
 * depth buffer as a height field, continuous between samples).  Here a
 * column's free depth ranges (before its first interval, between two)
 * are matched with the previous column's, starting at the centre's (the
 * range in front of it, where every ray leaving c starts): two ranges
 * with depths in common are one free space, the surfaces bounding them
 * being taken continuous between the columns; a ray passing from a free
 * range of one column to one of the next with no depth in common has
 * crossed a surface, and the angles where it does (the overlap of the two
 * ranges' arcs) are occupied.  The space behind a column's last surface
 * is outside the scene as the list shows it (the far side of a room's
 * wall): a ray cannot reach it from the centre's range without crossing
 * that surface, so a closed interval with no node behind it is solid
 * behind it, as is a node without back face (facing unknown, unmatched)
 * that is its list's last.  An unmatched node with nodes behind it is a
 * sheet, an interval of no thickness (obs__deep_sheets, deep_internal.h):
 * the facing flags say the space behind it is free, and taking it solid
 * behind (a horizon over the whole gap behind it) blocked every ray past
 * it: measured on the street scene, the darkening that grew with the
 * steps (each denser step a new chance to meet such a column; the
 * horizon is a maximum) was half of it away from the ray tracer's AO.
 * The visible set is what no arc occupies: the sum over the free arcs
 * [t0, t1] of a(t1) - a(t0).  The nodes solid behind them bound the side
 * by their highest horizon as before, and as every free range then starts
 * at the camera no crossing is found: with no closed interval the result
 * is a(h0) + a(h1) exactly.
 *
 * The search radius.  XeGTAO's falloff (gtao.c) moves a point's horizon
 * cosine towards the tangent's `low` by the weight w(r) of its distance
 * r: a node solid behind occupies [low, low + (shc - low) w], the
 * horizon form, kept for those nodes.  An arc is not a horizon: mapping
 * its end beyond the radius to the tangent (w = 0) turns [front, back]
 * into [back, tangent], the directions *under* the solid (the ground
 * under an animal's belly, whose back is beyond D and belly within it:
 * measured on zoo, the whole gap occupied).  The arcs take the true
 * angles instead, and a solid counts where a ray can meet it within the
 * radius R where the weight reaches 0 (the hard cut of the exact rows:
 * the ray tracer's distance).  A solid met between two columns (an
 * interval seen in the later one, or a crossing) is entered after the
 * ray left the earlier column and at the depths it occupies there (its
 * bounding surfaces continued between the columns at the depths they
 * have in the later one): the arc counts where the ray left the
 * earlier column within R (the angles of that column's chord of the
 * ball; the centre's: all) and reaches the solid's depths within R
 * (|cz - z| / |u_z| for the depth z of its near face and the ray's
 * direction u).  Both are lower bounds of the distance at which the ray
 * meets the surface, exact for a face at one depth (a slab parallel to
 * the image plane: test_deep.c, the wall under a raised slab), and they
 * converge to it as the columns get dense.  The receiver's own column
 * is free from the nearest surface in front of it (0 for the front
 * node; a hidden node's free range starts at the back face or node
 * before it). */
#include <math.h>

#include "chain/lanes.h"
#include "chain/mask_weight.h"
#include "methods/gtao_deep.h"

/* fminf and fmaxf as glibc computes them, inline (lanes.h): gcc calls
 * libm for them, several times per node */
static float clampf(float v, float lo, float hi) { return min_f(max_f(v, lo), hi); }
static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The cost (a pixel reads 2 x slices x 32 columns): most columns add no
 * arc (dining: 32 % of them call add_reach, 61 % of its calls have an
 * arc empty before the window), so what only an arc reads is taken where
 * it is first needed.  The angles from v of the columns' points are kept
 * as their cosines until an arc is added: acos is decreasing, so the
 * larger of two angles is the arc cosine of the smaller cosine, and a
 * clip that leaves an arc empty is seen on the cosines.  A column's ray
 * (its pixel's projection solved), its u_z and its window (the chord of
 * the ball and two cosines, read by the next column) wait for their
 * first reader.  The same arcs, bit for bit, as taking each angle first.
 * gtao.glsl keeps the cosines too, but computes the ray and window of
 * every column (llvmpipe runs both sides of a branch). */

/* the cosine of the angle of d from v (dist: |d|); low where d is 0 */
static float cos_v(const float d[3], float dist, const float v[3], float low)
{
    return dist > 0.0f ? dot3(d, v) / dist : low;
}

/* The horizon cosine of the point c + d (dist: |d|, shc: cos_v) moved
 * from the tangent's `low` by its falloff weight times om, as sample_cos
 * in gtao.c; low where d is 0: the horizon form of a node solid behind
 * it. */
static float weighted_cos(const float fw[3], const float d[3], float dist, float shc, float low,
                          float om)
{
    if (!(dist > 0.0f))
        return low;
    float dz = d[2] * (1.0f + fw[2]); /* thin-occluder compensation */
    /* gtao_thin 0 (its default): dz is d[2] and fb the distance */
    float fb = fw[2] == 0.0f ? dist : sqrtf(d[0] * d[0] + d[1] * d[1] + dz * dz);
    float w = clampf(fb * fw[0] + fw[1], 0.0f, 1.0f) * om;
    return low + (shc - low) * w;
}

/* The part of the column's ray o + s dir (s the planar depth) where the
 * falloff weight is not 0: the distance from c, measured as the weight
 * measures it (z scaled by 1 + gtao_thin), at most the radius where
 * the weight reaches 0, R = -fw[1] / fw[0] (gtao_setup: R at any
 * falloff range).  Writes the depths [s0, s1]; 0 where the ray passes
 * outside. */
static int chord(const float fw[3], const float o[3], const float dir[3], const float c[3],
                 float s[2])
{
    const float k = 1.0f + fw[2], r = -fw[1] / fw[0];
    const float a3[3] = {o[0] - c[0], o[1] - c[1], (o[2] - c[2]) * k};
    const float d3[3] = {dir[0], dir[1], dir[2] * k};
    const float a = dot3(d3, d3), b = dot3(a3, d3), cc = dot3(a3, a3) - r * r;
    const float disc = b * b - a * cc;
    if (!(disc > 0.0f) || !(a > 0.0f))
        return 0;
    const float sq = sqrtf(disc);
    s[0] = (-b - sq) / a;
    s[1] = (-b + sq) / a;
    return 1;
}

/* the cosine of the angle from v of the column's point at depth z, seen
 * from c */
static float depth_cos(const float o[3], const float dir[3], float z, const float c[3],
                       const float v[3], float low)
{
    const float d[3] = {o[0] + z * dir[0] - c[0], o[1] + z * dir[1] - c[1],
                        o[2] + z * dir[2] - c[2]};
    return clampf(cos_v(d, sqrtf(dot3(d, d)), v, low), -1.0f, 1.0f);
}

/* adds the occupied arc [lo, hi] to the side, sorted by lo */
static void add_arc(obs__gtao_side *s, float lo, float hi)
{
    if (!(hi > lo))
        return;
    int i = s->n;
    if (i == OBS__GTAO_MAX_ARCS) { /* not reached (the bound's comment): widen the last arc */
        s->lo[i - 1] = min_f(s->lo[i - 1], lo);
        s->hi[i - 1] = max_f(s->hi[i - 1], hi);
        return;
    }
    for (; i > 0 && s->lo[i - 1] > lo; i--) {
        s->lo[i] = s->lo[i - 1];
        s->hi[i] = s->hi[i - 1];
    }
    s->lo[i] = lo;
    s->hi[i] = hi;
    s->n++;
}

/* A column's pixel and, taken where first needed (most columns need
 * neither), its ray o + s dir (have_ray) and the slice's direction on
 * this side, u_z(t) = uz[0] cos(t - uz[1]) (have_uz); with what they
 * are measured against: the centre c (planar depth cz0), v, the side's
 * low and the falloff (fw). */
typedef struct column_ray {
    const obs__frame *f;
    const float *fw, *c, *v;
    float low, cz0;
    int qx, qy, have_ray, have_uz;
    float o[3], dir[3], uz[2];
} column_ray;

static void ray_of(column_ray *cr)
{
    float ndc[2];
    obs__px_ndc(cr->f, cr->qx, cr->qy, ndc);
    obs__view_ray(cr->f->proj, ndc, cr->o, cr->dir);
    cr->have_ray = 1;
}

static void ray_uz(column_ray *cr)
{
    if (!cr->have_ray)
        ray_of(cr);
    const float *v = cr->v, *o = cr->o, *dir = cr->dir, *c = cr->c;
    /* the ray's point at the centre's depth, less c */
    const float pc[3] = {o[0] + cr->cz0 * dir[0] - c[0], o[1] + cr->cz0 * dir[1] - c[1],
                         o[2] + cr->cz0 * dir[2] - c[2]};
    const float pv = dot3(pc, v);
    const float od[3] = {pc[0] - pv * v[0], pc[1] - pv * v[1], pc[2] - pv * v[2]};
    const float ol = sqrtf(dot3(od, od));
    cr->uz[0] = cr->uz[1] = 0.0f;
    if (ol > 0.0f) {
        cr->uz[0] = sqrtf(v[2] * v[2] + od[2] * od[2] / (ol * ol));
        cr->uz[1] = atan2f(od[2] / ol, v[2]);
    }
    cr->have_uz = 1;
}

/* The window of the side's last column (pixel s->wq; its ray wo + s wd
 * where it took it, win_at 2): the cosines of the angles where its ray
 * lies within the radius, the depths [cs0, cs1] of its chord of the
 * ball; empty (the cosines of angle 0) where it passes outside. */
static void side_window(obs__gtao_side *s, const column_ray *cr)
{
    column_ray w = *cr;
    float cs[2] = {0.0f, 0.0f};
    w.qx = s->wq[0];
    w.qy = s->wq[1];
    if (s->win_at == 2) /* that column took its ray */
        for (int i = 0; i < 3; i++) {
            w.o[i] = s->wo[i];
            w.dir[i] = s->wd[i];
        }
    else
        ray_of(&w);
    s->win[0] = s->win[1] = 1.0f;
    if (chord(cr->fw, w.o, w.dir, cr->c, cs) && cs[1] > 0.0f) {
        s->win[0] = depth_cos(w.o, w.dir, max_f(cs[0], 0.0f), cr->c, cr->v, cr->low);
        s->win[1] = depth_cos(w.o, w.dir, cs[1], cr->c, cr->v, cr->low);
    }
    s->win_at = 0;
}

/* Adds the arc of a solid met between the previous column and this one,
 * the angles whose cosines are [clo, chi] (clo >= chi), where it can lie
 * within the radius r: where the ray left the previous column within r
 * (the side's window) and reaches the solid's depths [zlo, zhi] within
 * r.  The solid lies at those depths (the surfaces bounding it continued
 * between the columns at the depths they have here), so a ray from c
 * (planar depth cz) meets it no nearer than where it reaches the band:
 * at |cz - z| / |u_z| for the band's near edge z, u the ray's direction;
 * in the slice u_z(t) = A cos(t - p0) (cr's uz: A and p0).  Both are
 * lower bounds of the distance of the surface crossed, exact for a face
 * at one depth. */
static void add_reach(obs__gtao_side *s, float clo, float chi, float zlo, float zhi,
                      column_ray *cr)
{
    const float pi = (float)M_PI, cz = cr->cz0;
    if (!(chi < clo))
        return; /* empty before the window's clip */
    if (s->win_at) /* the previous column's window, first needed */
        side_window(s, cr);
    /* the window's clip on the cosines: empty there where it is empty on
     * the angles (acos decreasing) */
    clo = min_f(clo, s->win[0]);
    chi = max_f(chi, s->win[1]);
    if (!(chi < clo))
        return;
    const float dz = cz < zlo ? zlo - cz : cz > zhi ? cz - zhi : 0.0f;
    if (!(dz > 0.0f)) { /* c at the band's depths */
        add_arc(s, acosf(clo), acosf(chi));
        return;
    }
    if (!cr->have_uz)
        ray_uz(cr);
    const float r = -cr->fw[1] / cr->fw[0];
    if (!(cr->uz[0] * r > dz))
        return; /* no ray of the slice reaches the band within r */
    const float lo = acosf(clo), hi = acosf(chi);
    const float half = acosf(dz / (r * cr->uz[0]));
    const float mid = cz > zhi ? cr->uz[1] : cr->uz[1] + pi; /* towards the camera: u_z > 0 */
    for (int i = -1; i <= 1; i++)
        add_arc(s, max_f(lo, mid + 2.0f * pi * (float)i - half),
                min_f(hi, mid + 2.0f * pi * (float)i + half));
}

void obs__gtao_side_start(obs__gtao_side *s, const float c[3], float z0)
{
    s->n = 0;
    s->gaps = 1;
    s->z[0][0] = min_f(z0, -c[2]);
    s->z[0][1] = -c[2];
    s->t[0][0] = s->win[0] = 1.0f; /* the angles 0 and pi */
    s->t[0][1] = s->win[1] = -1.0f;
    s->win_at = 0;
}

float obs__gtao_column(const obs__frame *f, const float fw[3], obs__gtao_side *s, const float *q,
                       const float *end, size_t plane, int layers, int x, int y, int self, int qx,
                       int qy, const float c[3], const float v[3], float low)
{
    float gz[OBS__GTAO_MAX_GAPS][2], gt[OBS__GTAO_MAX_GAPS][2]; /* gt: cosines */
    float hc = low, cz = 0.0f, ct = 1.0f; /* the free range open from depth cz (angle 0) */
    int ng = 0, open = 1, last = -1;
    column_ray cr = {f, fw, c, v, low, -c[2], qx, qy, 0, 0,
                     {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f}};
    /* the last node met outside every interval: if it closes an interval,
     * nothing lies behind that (solid behind it, the header), unless the
     * list was cut behind it (its last node's end OBS__DEEP_END_CUT,
     * deep_internal.h: -2) */
    int tail = -1;
    for (int k = 0; k < layers; k++)
        if (q[(size_t)k * plane + 3] > 0.0f) {
            tail = k;
            if (!(end && end[(size_t)k * (plane / 4)] < 0.0f))
                last = k;
        }
    if (end && tail >= 0 && end[(size_t)tail * (plane / 4)] < -1.5f)
        last = -1;
    for (int k = 0; k < layers; k++) {
        const float *qk = q + (size_t)k * plane;
        const float e = end && k != last ? end[(size_t)k * (plane / 4)] : 0.0f;
        if (!(qk[3] > 0.0f) || e < 0.0f)
            continue; /* empty, or inside a nearer node's interval */
        const float d[3] = {qk[0] - c[0], qk[1] - c[1], qk[2] - c[2]};
        const float dist = sqrtf(dot3(d, d)), shc = cos_v(d, dist, v, low);
        if (e == 0.0f) /* solid behind: the horizon form */
            hc = max_f(hc, weighted_cos(fw, d, dist, shc, low,
                                        obs__occluder_weight_node(f, x, y, self, qx, qy, k)));
        if (!open)
            continue; /* behind a node solid behind it: no free range */
        const float tf = clampf(shc, -1.0f, 1.0f); /* its true angle's cosine */
        if (qk[3] > cz && ng < OBS__GTAO_MAX_GAPS) { /* the free range in front of it */
            gz[ng][0] = cz, gz[ng][1] = qk[3];
            gt[ng][0] = ct, gt[ng][1] = tf;
            ng++;
        }
        if (e == 0.0f) {
            open = 0;
            continue;
        }
        /* a closed interval: the solid from its front face to its back
         * face on the pixel's ray (q = o + w dir, obs__prep_position),
         * the arc between their angles where a ray meets it within the
         * radius (add_reach) */
        cz = e;
        if (!cr.have_ray)
            ray_of(&cr);
        ct = depth_cos(cr.o, cr.dir, e, c, v, low);
        if (obs__occluder_weight_node(f, x, y, self, qx, qy, k) > 0.0f)
            add_reach(s, tf, ct, qk[3], e, &cr);
    }
    if (open && ng < OBS__GTAO_MAX_GAPS) { /* no surface from cz on */
        gz[ng][0] = cz, gz[ng][1] = INFINITY;
        gt[ng][0] = ct, gt[ng][1] = -1.0f; /* the angle pi */
        ng++;
    }
    /* a ray from a free range of the previous column to one of this
     * column with no depth in common crosses a surface between them,
     * counted where it can do so within the radius (add_reach) */
    for (int a = 0; a < s->gaps; a++)
        for (int b = 0; b < ng; b++) {
            if (s->z[a][0] < gz[b][1] && gz[b][0] < s->z[a][1])
                continue; /* one free space */
            /* the surface crossed lies at the depths between the two,
             * at the angles both ranges' arcs hold (the larger start,
             * the smaller end: on the cosines, the smaller and the
             * larger) */
            const int before = s->z[a][1] <= gz[b][0];
            add_reach(s, min_f(s->t[a][0], gt[b][0]), max_f(s->t[a][1], gt[b][1]),
                      before ? s->z[a][1] : gz[b][1], before ? gz[b][0] : s->z[a][0], &cr);
        }
    /* this column's window, for the next: the depths of its ray within
     * the radius (the header), taken where an arc needs them (most
     * columns add none) */
    s->wq[0] = qx;
    s->wq[1] = qy;
    s->win_at = 1;
    if (cr.have_ray) { /* kept: most windows taken follow a column that took its ray */
        for (int i = 0; i < 3; i++) {
            s->wo[i] = cr.o[i];
            s->wd[i] = cr.dir[i];
        }
        s->win_at = 2;
    }
    s->gaps = ng;
    for (int b = 0; b < ng; b++)
        for (int i = 0; i < 2; i++) {
            s->z[b][i] = gz[b][i];
            s->t[b][i] = gt[b][i];
        }
    return hc;
}

float obs__gtao_centre_start(const float *q, const float *end, size_t plane, int self)
{
    float z0 = 0.0f;
    for (int k = 0; k < self; k++) {
        const float w = q[(size_t)k * plane + 3], e = end[(size_t)k * (plane / 4)];
        if (w > 0.0f && e >= 0.0f)
            z0 = max_f(z0, e > 0.0f ? e : w);
    }
    return z0;
}

/* The free part of one side (s = +1: angles 0 .. h, s = -1: h .. 0):
 * the sweep over its arcs, sorted by their near end, each end clamped to
 * n's hemisphere as gtao.c clamps a horizon. */
static float side_free(const obs__gtao_side *a, float h, float s, float gamma, float cos_g)
{
    const float half_pi = (float)M_PI_2;
    if (a->n == 0)
        return obs__gtao_arc(h, gamma, cos_g);
    float end = s * h, cur = 0.0f, sum = 0.0f; /* |angles| on the side */
    for (int i = 0; i <= a->n; i++) {
        float lo = end, hi = end;
        if (i < a->n) {
            lo = s > 0.0f ? gamma + min_f(a->lo[i] - gamma, half_pi)
                          : gamma + max_f(-a->lo[i] - gamma, -half_pi);
            hi = s > 0.0f ? gamma + min_f(a->hi[i] - gamma, half_pi)
                          : gamma + max_f(-a->hi[i] - gamma, -half_pi);
            lo = min_f(s * lo, end);
            hi = s * hi;
        }
        if (lo > cur) /* free from cur to lo */
            sum += obs__gtao_arc(s * lo, gamma, cos_g) -
                   (cur > 0.0f ? obs__gtao_arc(s * cur, gamma, cos_g) : 0.0f);
        cur = max_f(cur, hi);
        if (cur >= end)
            break;
    }
    return sum;
}

float obs__gtao_slice_free(const obs__gtao_side *s0, const obs__gtao_side *s1, float h0, float h1,
                           float gamma, float cos_g)
{
    return side_free(s1, h0, -1.0f, gamma, cos_g) + side_free(s0, h1, 1.0f, gamma, cos_g);
}
