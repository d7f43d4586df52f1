/* The ray-traced ambient-occlusion reference of libobscura (Embree 3):
 * the ground truth the screen-space methods are measured against.
 *
 * Definition (the one of Cycles' AO pass): at the surface point p seen
 * through a pixel's centre, with shading normal n facing the camera,
 *   AO(p) = 1/pi * integral over the hemisphere of n of
 *           V(p, w, D) cos(n, w) dw,
 * V = 1 when a ray from p in direction w travels the distance D without
 * hitting anything (any face, front or back), else 0.  Estimated by Monte
 * Carlo with cosine-weighted directions (pdf cos/pi, so the estimate is
 * the fraction of unblocked rays); a direction below the triangle's own
 * plane counts as blocked.  No GL here; safe to call from any thread.
 *
 * Transparency (a scene with opacity, scene.h): V becomes the ray's
 * transmittance over D, the product of (1 - alpha) of every surface it
 * crosses (an opaque one: 0), so a ray within D of a surface of opacity
 * alpha is blocked by alpha.  The primary ray of a pixel crosses layers
 * k = 0, 1, ... (front to back, alpha_k > 0); each gets the AO of OITAO
 * eq 1 with the integral ray traced,
 *   AO_k = 1 - alpha_k (1 - V_k),  V_k = 1/pi integral T(p_k, w, D) cos dw,
 * and the pixel is their front-to-back alpha blend onto AO 1 (OITAO III,
 * the separated scheme: what core/deep/deep_cpu.c computes from the A-buffer),
 *   AO = sum_k alpha_k AO_k prod_{j<k} (1 - alpha_j) + prod_k (1 - alpha_k).
 * An opaque front surface gives the definition above.  G-buffer points
 * (obs_reference_view.position) are taken as opaque; only their rays are
 * attenuated.
 *
 * Obscurance mode (obs_reference_desc.obscurance): the quantity the bake
 * puts on the vertices (bake.h), eq 1 of "Baked ambient obscurance on the
 * vertices of game levels" at two distances d from the same rays,
 *   AO_d(p) = 1/pi integral over the hemisphere of rho(t(p, w)) cos dw,
 *   rho(x) = 1 - exp(a x), a = ln(0.5) / d,
 * t the distance to the closest hit (any face, front or back; a miss is
 * rho = 1; rays stop at 16 times the longer d), the hemisphere around the
 * geometric normal facing the viewer (the G-buffer's normal for G-buffer
 * points), the bake's own kernel, ray lattice and random shifts
 * (core/level/kernel.h).  Every surface is opaque, as the bake traces it:
 * opacities are not used; with desc.occluders the rays meet the bake's
 * occluders instead, the decorators' fog and semi-transparent trees
 * multiplying each ray's rho by their transmittance (section 2.1).  The image has three channels: the blend
 * b AO_short + (1 - b) AO_long, AO_short, AO_long.  With obscurance_near
 * D > 0, two more: AO_near, the AO of the definition above with distance
 * D at the same point (what a screen-space method of radius D estimates),
 * and AO_near x AO_long, the reference of both scales for the baked long
 * distance times screen-space AO (obs_result_combine_baked). */
#ifndef OBSCURA_REFERENCE_H
#define OBSCURA_REFERENCE_H

#include <stdint.h>

#include "obscura/obscura.h"
#include "obscura/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Called after each finished row (from a worker thread, one call at a
 * time): rows done so far and rows in all. */
typedef void (*obs_progress_fn)(void *user, int done, int total);

typedef struct obs_reference_desc {
    float distance;   /* D, the AO ray length in world units (> 0) */
    int spp;          /* rays per pixel; 0 -> 256 */
    uint64_t seed;    /* the image depends on the seed only, not on threads */
    int threads;      /* worker threads; 0 -> CPUs online (at most 64) */
    obs_progress_fn progress; /* may be NULL */
    void *progress_user;
    /* Obscurance mode (above) when set; distance is then unused. */
    int obscurance;
    float obscurance_distance[2]; /* short, long (> 0) */
    float blend;                  /* weight of the short one, in [0, 1] */
    float obscurance_near;        /* > 0: the AO at this distance too */
    /* Obscurance mode: what its rays meet, as the bake's do (bake.h,
     * obs_bake_occluders_new: shrubs as fog, trees semi-transparent,
     * section 2.1), instead of the scene's surfaces; NULL: the scene,
     * every surface opaque.  The primary rays still see the scene. */
    const struct obs_bake_occluders *occluders;
} obs_reference_desc;

/* Where the AO is evaluated: the first hit of a primary ray from the
 * camera through each pixel centre, or, with `position` set, the points of
 * a G-buffer (3 channels, world space) with their normals (3 channels,
 * world space, flipped to face the camera when they do not); a pixel with
 * a non-finite position, one beyond OBS_SCENE_MAX_COORD or a zero normal
 * is background.  The camera is required in both cases (it gives the
 * depth and the view direction); one placed beyond OBS_SCENE_MAX_COORD,
 * or whose corner rays overflow float, is OBS_NO_CAMERA. */
typedef struct obs_reference_view {
    const obs_camera *camera;  /* world_to_camera + projection */
    int width, height;         /* image size (camera rays) */
    const obs_image *position; /* or G-buffer points (width, height from */
    const obs_image *normal;   /* them), both or neither */
} obs_reference_view;

/* The AO estimate (1 channel, 1 = unoccluded, 1 where nothing is hit;
 * obscurance mode: 3 channels, blend, short, long, or 5 with near, near x
 * long; all 1 there) and, when depth is non-NULL, the planar view depth of the points (the
 * front layer's with opacities; OBS_SKY_DEPTH where there is none).  Caller frees both with
 * obs_image_free(). */
obs_status obs_reference_render(const obs_scene *scene, const obs_reference_view *view,
                                const obs_reference_desc *desc, obs_image *ao,
                                obs_image *depth, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
