/* The table of AO methods (methods.h) and the AO pass of the comparison
 * methods (hemisphere, angle, hbao, gtao), which take the place of the VAO
 * estimator in the chain: the CPU twin of method.frag.glsl. */
#include <math.h>

#include "methods/methods.h"
#include "obs_shaders.h"

/* Each method's setup: its fields of the frame (frame.h), after the
 * radius is resolved. */
static void hemisphere_setup(const obs_params *p, obs__frame *f)
{
    f->hs_count = p->hemisphere_samples;
    f->hs_bias = p->hemisphere_bias * f->radius;
    obs__hemisphere_kernel(f->hs_count, &f->hs_kernel[0][0]);
}

static void angle_setup(const obs_params *p, obs__frame *f)
{
    f->angle_pairs = p->angle_pairs;
    obs__angle_pattern(f->angle_pairs, &f->angle_xy[0][0]);
    f->angle_acos = p->angle_acos;
}

static void hbao_setup(const obs_params *p, obs__frame *f)
{
    f->hbao_dirs = p->hbao_directions;
    f->hbao_steps = p->hbao_steps;
    for (int d = 0; d < f->hbao_dirs; d++) { /* HBAO: Nd directions over 2 pi */
        double a = 2.0 * M_PI * d / f->hbao_dirs;
        f->hbao_dir[d][0] = (float)cos(a);
        f->hbao_dir[d][1] = (float)sin(a);
    }
    f->hbao_bias_cs[0] = (float)cos(p->hbao_angle_bias * M_PI / 180.0);
    f->hbao_bias_cs[1] = (float)sin(p->hbao_angle_bias * M_PI / 180.0);
}

static void gtao_setup(const obs_params *p, obs__frame *f)
{
    f->gtao_slices = p->gtao_slices;
    f->gtao_steps = p->gtao_steps;
    f->gtao_heuristics = p->gtao_heuristics == OBS_ON;
    /* XeGTAO: effectRadius = EffectRadius * RadiusMultiplier; the falloff
     * range is EffectFalloffRange * effectRadius, and a sample at
     * distance r weighs saturate(r * falloffMul + falloffAdd), 1 up to
     * falloffFrom = effectRadius (1 - EffectFalloffRange), 0 at the
     * radius */
    float R = f->radius * p->gtao_radius_multiplier, range = p->gtao_falloff * R;
    f->gtao_radius = R;
    f->gtao_falloff[0] = -1.0f / range;
    f->gtao_falloff[1] = R * (1.0f - p->gtao_falloff) / range + 1.0f;
    f->gtao_thin_power[0] = p->gtao_thin;
    f->gtao_thin_power[1] = p->gtao_power;
}

/* The methods' twins behind one signature (GLSL: method_ao()). */
static float hemisphere_ao(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                           const float n[3], int *count)
{
    *count = f->hs_count;
    return obs__hemisphere_pixel(f, pos, x, y, p, n);
}

static float angle_ao(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                      const float n[3], int *count)
{
    *count = 2 * f->angle_pairs;
    return obs__angle_pixel(f, pos, x, y, p, n);
}

static float hbao_ao(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                     const float n[3], int *count)
{
    return obs__hbao_pixel(f, pos, x, y, p, n, count);
}

static float gtao_ao(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                     const float n[3], int *count)
{
    return obs__gtao_pixel(f, pos, x, y, p, n, count);
}

/* Samples per pixel, for obs_frame_cost. */
static int vao_samples(const obs_params *p) { return p->samples; }
static int hemisphere_samples(const obs_params *p) { return p->hemisphere_samples; }
static int angle_samples(const obs_params *p) { return 2 * p->angle_pairs; }
static int hbao_samples(const obs_params *p) { return p->hbao_directions * p->hbao_steps; }
static int gtao_samples(const obs_params *p) { return 2 * p->gtao_slices * p->gtao_steps; }

#define F(field) offsetof(obs__frame, field)

/* In the order of OBS_METHOD_LIST (params.h). */
static const obs__method methods[] = {
    {OBS_METHOD_VAOPP, "vaopp", NULL, NULL, NULL, vao_samples, {{NULL}}, 1},
    {OBS_METHOD_VAO, "vao", NULL, NULL, NULL, vao_samples, {{NULL}}, 1},
    {OBS_METHOD_HEMISPHERE, "hemisphere", obs__shader_hemisphere, hemisphere_setup, hemisphere_ao,
     hemisphere_samples,
     {{"u_hs_count", OBS__U_INT, F(hs_count), 0, 0},
      {"u_hs_bias", OBS__U_FLOAT, F(hs_bias), 0, 0},
      {"u_hs_kernel", OBS__U_FLOAT, F(hs_kernel), F(hs_count), 3},
      {NULL}},
     1},
    {OBS_METHOD_ANGLE, "angle", obs__shader_angle, angle_setup, angle_ao, angle_samples,
     {{"u_angle_pairs", OBS__U_INT, F(angle_pairs), 0, 0},
      {"u_angle_xy", OBS__U_VEC2, F(angle_xy), F(angle_pairs), 1},
      {"u_angle_acos", OBS__U_INT, F(angle_acos), 0, 0},
      {NULL}},
     0},
    {OBS_METHOD_HBAO, "hbao", obs__shader_hbao, hbao_setup, hbao_ao, hbao_samples,
     {{"u_hbao_dirs", OBS__U_INT, F(hbao_dirs), 0, 0},
      {"u_hbao_steps", OBS__U_INT, F(hbao_steps), 0, 0},
      {"u_hbao_dir", OBS__U_VEC2, F(hbao_dir), F(hbao_dirs), 1},
      {"u_hbao_bias_cs", OBS__U_VEC2, F(hbao_bias_cs), 0, 0},
      {NULL}},
     0},
    {OBS_METHOD_GTAO, "gtao", obs__shader_gtao, gtao_setup, gtao_ao, gtao_samples,
     {{"u_gtao_slices", OBS__U_INT, F(gtao_slices), 0, 0},
      {"u_gtao_steps", OBS__U_INT, F(gtao_steps), 0, 0},
      {"u_gtao_heuristics", OBS__U_INT, F(gtao_heuristics), 0, 0},
      {"u_gtao_radius", OBS__U_FLOAT, F(gtao_radius), 0, 0},
      {"u_gtao_falloff", OBS__U_VEC2, F(gtao_falloff), 0, 0},
      {"u_gtao_thin_power", OBS__U_VEC2, F(gtao_thin_power), 0, 0},
      {NULL}},
     0},
};
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
    return m->pixel(f, pos, x, y, p, n, count);
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
