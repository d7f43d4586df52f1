/* The VAO++ sample generator (section 4.5): rotation-aware Poisson-disk
 * sets on the unit disk, the best permutation of rotations, z-order.
 *
 * Every pixel uses the set rotated by one of 9 angles 2 pi k / 9 (the 3x3
 * tile of obs__pixel_rotation), so what the blurred image sees is the union
 * of the 9 rotations of the set.  The generator therefore places each new
 * point far from every existing point AND all of their rotations
 * ("ensures that it will be far enough from all the other points including
 * their rotations"), then chooses which rotation each sample takes so that
 * one pixel's own set is spread out too, then sorts by z-order.
 *
 * Its output is checked in as core/chain/sample_tables.c (`make samples`, which
 * runs `obscura samples --c`); tests/unit/core/test_samples.c regenerates
 * the tables and compares them exactly.  Everything here is plain double
 * arithmetic in a fixed order with a fixed seed, so the result does not
 * depend on the machine. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

#define ROTS 9            /* the 3x3 tile's angles, 2 pi k / 9 */
#define CANDIDATES 1024   /* best-candidate darts per placed point */
#define TRIALS 16         /* independent sets per size; the best is kept */
#define GROUP 8           /* permutation search: exhaustive within 8 */

typedef struct pt {
    double x, y;
} pt;

static double rc[ROTS], rs[ROTS]; /* cos, sin of 2 pi k / 9 */
static pthread_once_t rot_once = PTHREAD_ONCE_INIT;

static void init_rotations(void)
{
    for (int k = 0; k < ROTS; k++) {
        /* the same angles as obs__pixel_rotation() */
        double a = 2.0 * M_PI * k / ROTS;
        rc[k] = cos(a);
        rs[k] = sin(a);
    }
}

static pt rotate(pt p, int k)
{
    return (pt){rc[k] * p.x - rs[k] * p.y, rs[k] * p.x + rc[k] * p.y};
}

static double dist(pt a, pt b) { return sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y)); }

/* splitmix64: a fixed, portable sequence. */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double next_unit(uint64_t *s) { return (double)(next_u64(s) >> 11) / 9007199254740992.0; }

/* The spacing score of candidate c against the points placed so far: the
 * smallest distance to a point or (rotation-aware) to any of its 9
 * rotations, and to c's own other rotations (they too are samples of the
 * union).  The disk's edge counts as a mirror: a point d/2 from the edge
 * is as far from its mirror image as from a neighbour d away.  Without
 * this, maximising the spacing pushes points onto the rim, where the pipes
 * are short (sqrt(1 - x^2 - y^2) -> 0, eq 2) and the disk's area is no
 * longer sampled uniformly as eq 1 assumes. */
static double score(pt c, const pt *p, int placed, int aware)
{
    double r = sqrt(c.x * c.x + c.y * c.y);
    double best = 2.0 * (1.0 - r);
    if (aware) /* the nearest own rotation is one step, 2 pi / 9, away */
        best = fmin(best, 2.0 * r * sin(M_PI / ROTS));
    for (int j = 0; j < placed; j++)
        for (int k = 0; k < (aware ? ROTS : 1); k++)
            best = fmin(best, dist(c, rotate(p[j], k)));
    return best;
}

/* Mitchell's best candidate, an approximation of Poisson-disk sampling
 * that places exactly n points: each point is the candidate (area-uniform
 * on the disk) with the largest spacing score. */
static void poisson(int n, int aware, uint64_t seed, pt *p)
{
    for (int i = 0; i < n; i++) {
        double best = -1.0;
        for (int c = 0; c < CANDIDATES; c++) {
            double r = sqrt(next_unit(&seed)), a = 2.0 * M_PI * next_unit(&seed);
            pt q = {r * cos(a), r * sin(a)};
            double s = score(q, p, i, aware);
            if (s > best) {
                best = s;
                p[i] = q;
            }
        }
    }
}

double obs__samples_min_distance(const float *xy, int n, int rotations)
{
    pthread_once(&rot_once, init_rotations);
    double best = INFINITY;
    int rots = rotations ? ROTS : 1;
    for (int i = 0; i < n; i++)
        for (int j = i; j < n; j++)
            for (int k = 0; k < rots; k++) {
                if (i == j && k == 0)
                    continue;
                pt a = {xy[2 * i], xy[2 * i + 1]}, b = {xy[2 * j], xy[2 * j + 1]};
                best = fmin(best, dist(a, rotate(b, k)));
            }
    return best;
}

/* ---- best permutation of rotations ------------------------------------ */

/* The group being permuted: m points, each to take a distinct rotation.
 * pair[i][a][j][b] = |R_a p_i - R_b p_j|; fixed[i][a] = sum of the
 * distances of R_a p_i to the samples of earlier groups (already fixed). */
typedef struct perm_search {
    int m;
    double pair[GROUP][ROTS][GROUP][ROTS];
    double fixed[GROUP][ROTS];
    int cur[GROUP], best[GROUP];
    double best_sum;
} perm_search;

static void search(perm_search *s, int i, unsigned used, double sum)
{
    if (i == s->m) {
        if (sum > s->best_sum) { /* strict: the first best in search order wins */
            s->best_sum = sum;
            memcpy(s->best, s->cur, sizeof s->best);
        }
        return;
    }
    for (int a = 0; a < ROTS; a++) {
        if (used & (1u << a))
            continue;
        double add = s->fixed[i][a];
        for (int j = 0; j < i; j++)
            add += s->pair[i][a][j][s->cur[j]];
        s->cur[i] = a;
        search(s, i + 1, used | (1u << a), sum + add);
    }
}

/* Section 4.5: "we select the best permutation of rotated samples so that
 * sum of their distances from each other is maximal ... For sample-sets of
 * size 8 and less it is feasible to test all permutations. For larger
 * sets, we incrementally add groups of 8 samples and look for best
 * permutation of last group with fixed previous groups."  Each sample of a
 * group takes a different one of the 9 rotations (a permutation); the
 * union over the tile is unchanged, one pixel's set is spread out.  In the
 * first group the first sample keeps rotation 0: turning the whole set
 * changes no distance. */
static int best_rotations(pt *p, int n)
{
    perm_search *s = malloc(sizeof *s); /* ~42 KB: not on the stack */
    if (!s)
        return -1;
    for (int g = 0; g < n; g += GROUP) {
        memset(s, 0, sizeof *s);
        s->m = n - g < GROUP ? n - g : GROUP;
        s->best_sum = -1.0;
        for (int i = 0; i < s->m; i++)
            for (int a = 0; a < ROTS; a++) {
                pt q = rotate(p[g + i], a);
                for (int j = 0; j < g; j++)
                    s->fixed[i][a] += dist(q, p[j]);
                for (int j = 0; j < s->m; j++)
                    for (int b = 0; b < ROTS; b++)
                        s->pair[i][a][j][b] = dist(q, rotate(p[g + j], b));
            }
        if (g == 0) {
            s->cur[0] = 0;
            search(s, 1, 1u, 0.0);
        } else {
            search(s, 0, 0u, 0.0);
        }
        for (int i = 0; i < s->m; i++)
            p[g + i] = rotate(p[g + i], s->best[i]);
    }
    free(s);
    return 0;
}

/* ---- z-order ----------------------------------------------------------- */

static uint32_t spread16(uint32_t v)
{
    v &= 0xffff;
    v = (v | (v << 8)) & 0x00ff00ffu;
    v = (v | (v << 4)) & 0x0f0f0f0fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

/* Morton code of a point of [-1, 1]^2 on a 65536^2 grid, y above x. */
static uint32_t morton(pt p)
{
    uint32_t qx = (uint32_t)floor((p.x + 1.0) * 0.5 * 65535.0 + 0.5);
    uint32_t qy = (uint32_t)floor((p.y + 1.0) * 0.5 * 65535.0 + 0.5);
    return spread16(qx) | (spread16(qy) << 1);
}

/* Section 4.5: "samples are sorted according to the z-order, so that
 * samples spatially close in the scene are also close to each other in
 * memory".  Insertion sort: stable, n <= 32. */
static void z_order(pt *p, int n)
{
    for (int i = 1; i < n; i++) {
        pt v = p[i];
        uint32_t key = morton(v);
        int j = i - 1;
        for (; j >= 0 && morton(p[j]) > key; j--)
            p[j + 1] = p[j];
        p[j + 1] = v;
    }
}

/* ---- the sets ---------------------------------------------------------- */

static int valid_size(int n) { return n >= 2 && n <= OBS_MAX_SAMPLES && (n & (n - 1)) == 0; }

obs_status obs__samples_generate_ex(int n, int mode, float *xy)
{
    int rotation_aware = mode != OBS__SAMPLES_PLAIN;
    pt p[OBS_MAX_SAMPLES], trial[OBS_MAX_SAMPLES];
    if (!valid_size(n) || !xy)
        return OBS_INVALID_ARGUMENT;
    pthread_once(&rot_once, init_rotations);
    /* The best of TRIALS best-candidate runs (fixed seeds), judged by the
     * property the generator is for: the smallest spacing between the
     * samples and (rotation-aware) all their rotations, the rim counted
     * as in score(). */
    double best = -1.0;
    for (int t = 0; t < TRIALS; t++) {
        uint64_t seed = 0x5eed0a0ull * 1000003ull + (uint64_t)n * 131ull + (uint64_t)t;
        poisson(n, rotation_aware, seed, trial);
        double s = INFINITY;
        for (int i = 0; i < n; i++)
            s = fmin(s, score(trial[i], trial, i, rotation_aware));
        if (s > best) {
            best = s;
            memcpy(p, trial, sizeof(pt) * (size_t)n);
        }
    }
    if (mode == OBS__SAMPLES_VAOPP) {
        if (best_rotations(p, n) != 0)
            return OBS_NO_MEMORY;
        z_order(p, n);
    }
    for (int i = 0; i < n; i++) {
        xy[2 * i] = (float)p[i].x;
        xy[2 * i + 1] = (float)p[i].y;
    }
    return OBS_OK;
}

obs_status obs_samples_generate(int n, float *xy)
{
    return obs__samples_generate_ex(n, OBS__SAMPLES_VAOPP, xy);
}
