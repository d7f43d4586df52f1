/* Small shared helpers: error messages, checked sizes, 4x4 matrices. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "internal.h"

double obs__now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

int obs__size_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a)
        return -1;
    *out = a * b;
    return 0;
}

int obs__size_mul3(size_t a, size_t b, size_t c, size_t *out)
{
    size_t ab;
    if (obs__size_mul(a, b, &ab) != 0)
        return -1;
    return obs__size_mul(ab, c, out);
}

/* Array i's bytes rounded up to the alignment of any type. */
static size_t padded(size_t bytes)
{
    const size_t align = _Alignof(max_align_t);
    return ((bytes ? bytes : 1) + align - 1) / align * align;
}

void *obs__alloc_arrays(size_t n, const size_t *bytes, void **arr)
{
    size_t total = 0;
    for (size_t i = 0; i < n; i++) {
        if (bytes[i] > SIZE_MAX - _Alignof(max_align_t) - total)
            return NULL;
        total += padded(bytes[i]);
    }
    unsigned char *block = calloc(1, total ? total : 1);
    for (size_t i = 0, at = 0; block && i < n; at += padded(bytes[i]), i++)
        arr[i] = block + at;
    return block;
}

obs_status obs_check_size(const obs_limits *lim, int64_t width, int64_t height,
                          char err[OBS_ERR_LEN])
{
    int64_t max_w = lim && lim->max_width > 0 ? lim->max_width : 16384;
    int64_t max_h = lim && lim->max_height > 0 ? lim->max_height : 16384;
    uint64_t max_px = lim && lim->max_pixels > 0 ? lim->max_pixels
                                                 : (uint64_t)max_w * (uint64_t)max_h;
    if (width <= 0 || height <= 0)
        return obs__fail(err, OBS_BAD_FILE, "image size %lldx%lld is empty or negative",
                         (long long)width, (long long)height);
    if (width > max_w || height > max_h)
        return obs__fail(err, OBS_TOO_LARGE, "image size %lldx%lld exceeds the limit %lldx%lld",
                         (long long)width, (long long)height, (long long)max_w,
                         (long long)max_h);
    if ((uint64_t)width * (uint64_t)height > max_px)
        return obs__fail(err, OBS_TOO_LARGE, "image of %llu pixels exceeds the limit of %llu pixels",
                         (unsigned long long)((uint64_t)width * (uint64_t)height),
                         (unsigned long long)max_px);
    return OBS_OK;
}

size_t obs__plane_stride(const obs_plane *p, int width)
{
    return p->row_stride ? p->row_stride : (size_t)width * (size_t)p->channels * sizeof(float);
}

const float *obs__plane_px(const obs_plane *p, int width, int x, int y)
{
    const char *row = (const char *)p->data + (size_t)y * obs__plane_stride(p, width);
    return (const float *)row + (size_t)x * (size_t)p->channels;
}

/* ---- 4x4 matrices, row-major, column-vector convention ------------------ */

void obs__mat4_identity(float m[16])
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1.0f;
}

void obs__mat4_mul(const float a[16], const float b[16], float out[16])
{
    float r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += (double)a[i * 4 + k] * b[k * 4 + j];
            r[i * 4 + j] = (float)s;
        }
    memcpy(out, r, sizeof r);
}

void obs__mat4_transpose(const float m[16], float out[16])
{
    float r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r[j * 4 + i] = m[i * 4 + j];
    memcpy(out, r, sizeof r);
}

void obs__mat4_apply(const float m[16], const float v[4], float out[4])
{
    float r[4];
    for (int i = 0; i < 4; i++)
        r[i] = m[i * 4 + 0] * v[0] + m[i * 4 + 1] * v[1] + m[i * 4 + 2] * v[2] +
               m[i * 4 + 3] * v[3];
    memcpy(out, r, sizeof r);
}

double obs__tri_normal(const float p0[3], const float p1[3], const float p2[3], float n[3])
{
    float e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = p1[k] - p0[k];
        e2[k] = p2[k] - p0[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    double scale = (double)e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2] + e2[0] * e2[0] +
                   e2[1] * e2[1] + e2[2] * e2[2];
    if (!(len > 1e-7 * scale) || !isfinite(len)) {
        n[0] = n[1] = n[2] = 0.0f;
        return 0.0;
    }
    return len;
}

/* Gauss-Jordan elimination with partial pivoting, in double. */
int obs__mat4_invert(const float m[16], float out[16])
{
    double a[4][8];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            a[i][j] = m[i * 4 + j];
            a[i][j + 4] = (i == j);
        }
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (fabs(a[piv][c]) < 1e-12)
            return -1;
        if (piv != c)
            for (int j = 0; j < 8; j++) {
                double t = a[c][j];
                a[c][j] = a[piv][j];
                a[piv][j] = t;
            }
        double inv = 1.0 / a[c][c];
        for (int j = 0; j < 8; j++)
            a[c][j] *= inv;
        for (int r = 0; r < 4; r++) {
            if (r == c)
                continue;
            double f = a[r][c];
            for (int j = 0; j < 8; j++)
                a[r][j] -= f * a[c][j];
        }
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            out[i * 4 + j] = (float)a[i][j + 4];
    return 0;
}
