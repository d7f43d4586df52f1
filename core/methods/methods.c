/* The table of AO methods (methods.h) and the AO pass of the comparison
 * methods (hemisphere, angle, hbao, gtao), which take the place of the VAO
 * estimator in the chain: the CPU twin of method.frag.glsl. */
#include <math.h>

#include "methods/angle.h"
#include "methods/gtao.h"
#include "methods/hbao.h"
#include "methods/hemisphere.h"
#include "methods/methods.h"
#include "obs_shaders.h"

/* The methods' twins behind one signature (GLSL: method_ao()). */
static float hemisphere_ao(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                           const float p[4], const float n[3], int *count)
{
    (void)nrm;
    *count = obs__hemisphere_of(f)->count;
    return obs__hemisphere_pixel(f, pos, x, y, p, n);
}

static float angle_ao(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                      const float p[4], const float n[3], int *count)
{
    (void)nrm;
    *count = 2 * obs__angle_of(f)->pairs;
    return obs__angle_pixel(f, pos, x, y, p, n);
}

static float hbao_ao(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                     const float p[4], const float n[3], int *count)
{
    (void)nrm;
    return obs__hbao_pixel(f, pos, x, y, p, n, count);
}

static float gtao_ao(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                     const float p[4], const float n[3], int *count)
{
    return obs__gtao_pixel(f, pos, nrm, x, y, p, n, count);
}

static float hemisphere_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                             const float p[4], const float n[3], int *count, float bent[3])
{
    (void)nrm;
    *count = obs__hemisphere_of(f)->count;
    return obs__hemisphere_pixel_bent(f, pos, x, y, p, n, bent);
}

static float angle_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        const float p[4], const float n[3], int *count, float bent[3])
{
    (void)nrm;
    *count = 2 * obs__angle_of(f)->pairs;
    return obs__angle_pixel_bent(f, pos, x, y, p, n, bent);
}

static float hbao_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                       const float p[4], const float n[3], int *count, float bent[3])
{
    (void)nrm;
    return obs__hbao_pixel_bent(f, pos, x, y, p, n, count, bent);
}

static float gtao_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                       const float p[4], const float n[3], int *count, float bent[3])
{
    return obs__gtao_pixel_bent(f, pos, nrm, x, y, p, n, count, bent);
}

/* Samples per pixel, for obs_frame_cost. */
static int vao_samples(const obs_params *p) { return p->samples; }
static int hemisphere_samples(const obs_params *p) { return p->hemisphere_samples; }
static int angle_samples(const obs_params *p) { return 2 * p->angle_pairs; }
static int hbao_samples(const obs_params *p) { return p->hbao_directions * p->hbao_steps; }
static int gtao_samples(const obs_params *p) { return 2 * p->gtao_slices * p->gtao_steps; }

/* A uniform's value in the method's state type, at its place in the frame. */
#define F(type, field) (offsetof(obs__frame, ms) + offsetof(type, field))
#define HS(field) F(obs__hemisphere_state, field)
#define AN(field) F(obs__angle_state, field)
#define HB(field) F(obs__hbao_state, field)
#define GT(field) F(obs__gtao_state, field)

/* In the order of OBS_METHOD_LIST (params.h). */
static const obs__method methods[] = {
    {OBS_METHOD_VAOPP, "vaopp", NULL, NULL, NULL, vao_samples, {{NULL}}, 1},
    {OBS_METHOD_VAO, "vao", NULL, NULL, NULL, vao_samples, {{NULL}}, 1},
    {OBS_METHOD_HEMISPHERE, "hemisphere", obs__shader_hemisphere, obs__hemisphere_setup, hemisphere_ao,
     hemisphere_samples,
     {{"u_hs_count", OBS__U_INT, HS(count), 0, 0},
      {"u_hs_bias", OBS__U_FLOAT, HS(bias), 0, 0},
      {"u_hs_kernel", OBS__U_FLOAT, HS(kernel), HS(count), 3},
      {NULL}},
     1, hemisphere_bent},
    {OBS_METHOD_ANGLE, "angle", obs__shader_angle, obs__angle_setup, angle_ao, angle_samples,
     {{"u_angle_pairs", OBS__U_INT, AN(pairs), 0, 0},
      {"u_angle_xy", OBS__U_VEC2, AN(xy), AN(pairs), 1},
      {"u_angle_acos", OBS__U_INT, AN(acos), 0, 0},
      {NULL}},
     0, angle_bent},
    {OBS_METHOD_HBAO, "hbao", obs__shader_hbao, obs__hbao_setup, hbao_ao, hbao_samples,
     {{"u_hbao_dirs", OBS__U_INT, HB(dirs), 0, 0},
      {"u_hbao_steps", OBS__U_INT, HB(steps), 0, 0},
      {"u_hbao_dir", OBS__U_VEC2, HB(dir), HB(dirs), 1},
      {"u_hbao_bias_cs", OBS__U_VEC2, HB(bias_cs), 0, 0},
      {NULL}},
     1, hbao_bent},
    {OBS_METHOD_GTAO, "gtao", obs__shader_gtao, obs__gtao_setup, gtao_ao, gtao_samples,
     {{"u_gtao_slices", OBS__U_INT, GT(slices), 0, 0},
      {"u_gtao_steps", OBS__U_INT, GT(steps), 0, 0},
      {"u_gtao_heuristics", OBS__U_INT, GT(heuristics), 0, 0},
      {"u_gtao_radius", OBS__U_FLOAT, GT(radius), 0, 0},
      {"u_gtao_falloff", OBS__U_VEC2, GT(falloff), 0, 0},
      {"u_gtao_thin_power", OBS__U_VEC2, GT(thin_power), 0, 0},
      {NULL}},
     1, gtao_bent},
};
#undef GT
#undef HB
#undef AN
#undef HS
#undef F

#define METHOD_COUNT ((int)(sizeof methods / sizeof methods[0]))
_Static_assert(METHOD_COUNT == OBS_METHOD_COUNT - 1, "a row for every OBS_METHOD_* (params.h)");

int obs__method_count(void) { return METHOD_COUNT; }

const obs__method *obs__method_at(int i)
{
    return i >= 0 && i < METHOD_COUNT ? &methods[i] : NULL;
}

const obs__method *obs__method_get(int id)
{
    const obs__method *m = obs__method_at(id - OBS_METHOD_VAOPP);
    return m && (int)m->id == id ? m : NULL;
}

obs_status obs__frame_setup(obs_ctx *log_ctx, const obs_gbuffer *gb, const obs_params *p,
                            obs__frame *f, char err[OBS_ERR_LEN])
{
    obs_status s = obs__frame_setup_common(log_ctx, gb, p, f, err);
    /* The comparison methods' AO runs in place of the VAO estimator, the
     * rest of the chain is shared; each fills its own values. */
    const obs__method *m = obs__method_get(f->method);
    if (s == OBS_OK && m && m->setup)
        m->setup(p, f);
    return s;
}

/* GLSL: main() of method.frag.glsl */
float obs__method_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        int *count)
{
    size_t i = (size_t)y * (size_t)f->width + (size_t)x;
    const float *p = pos + 4 * i, *n = nrm + 3 * i;
    const obs__method *m = obs__method_get(f->method);
    *count = 0;
    if (!(p[3] > 0.0f) || !m || !m->pixel)
        return 1.0f;
    return m->pixel(f, pos, nrm, x, y, p, n, count);
}

float obs__method_pixel_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                             int *count, float bent[3])
{
    size_t i = (size_t)y * (size_t)f->width + (size_t)x;
    const float *p = pos + 4 * i, *n = nrm + 3 * i;
    const obs__method *m = obs__method_get(f->method);
    bent[0] = bent[1] = bent[2] = 0.0f;
    if (!m || !m->pixel_bent || !(p[3] > 0.0f))
        return obs__method_pixel(f, pos, nrm, x, y, count);
    *count = 0;
    float ao = m->pixel_bent(f, pos, nrm, x, y, p, n, count, bent);
    if (bent[0] == 0.0f && bent[1] == 0.0f && bent[2] == 0.0f) /* nothing open: the normal */
        for (int k = 0; k < 3; k++)
            bent[k] = n[k];
    return ao;
}

unsigned long long obs_frame_cost(const obs_params *params, int width, int height, int deep_layers)
{
    obs_params p;
    obs_params_resolve(params, &p);
    const obs__method *m = obs__method_get(p.method);
    if (!m || width <= 0 || height <= 0)
        return 0;
    unsigned long long n = (unsigned long long)width * (unsigned long long)height *
                           (unsigned long long)m->samples_per_pixel(&p);
    if (deep_layers > 1)
        n *= (unsigned long long)deep_layers * (unsigned long long)deep_layers;
    return n;
}
