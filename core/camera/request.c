/* The camera from a request: the plain field-of-view camera, fitting a
 * projection to an image's aspect, the matrices a binary request carried,
 * and the camera a frame is computed with (the G-buffer's, overridden by
 * parameters: HTTP query/JSON fields, CLI flags).  No file formats here
 * (core/camera/exr.c, json.c). */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "obscura/io.h"

#define OBS__PI 3.14159265358979323846

int obs_camera_fit_aspect(obs_camera *cam, int width, int height)
{
    float *P = cam->projection; /* row-major */
    if (width <= 0 || height <= 0 || P[14] != -1.0f || P[15] != 0.0f || P[1] != 0.0f ||
        P[2] != 0.0f || P[4] != 0.0f || P[6] != 0.0f)
        return 0;
    float x = P[5] * (float)height / (float)width;
    if (x == P[0])
        return 0;
    P[0] = x;
    return 1;
}

void obs_camera_from_fov(float fov_y_deg, float aspect, float near_z, float far_z, obs_camera *cam)
{
    const double f = 1.0 / tan(fov_y_deg * 3.14159265358979323846 / 360.0);
    memset(cam, 0, sizeof *cam);
    obs__mat4_identity(cam->world_to_camera);
    cam->projection[0] = (float)(f / aspect);
    cam->projection[5] = (float)f;
    cam->projection[10] = -(far_z + near_z) / (far_z - near_z);
    cam->projection[11] = -2.0f * far_z * near_z / (far_z - near_z);
    cam->projection[14] = -1.0f;
    cam->has_projection = 1;
    cam->source = OBS_CAMERA_PARAMS;
}

void obs_camera_from_request(obs_camera *cam, int has_world_to_camera, int has_projection)
{
    cam->has_world_to_camera = !!has_world_to_camera;
    cam->has_projection = !!has_projection;
    cam->source = cam->has_projection ? OBS_CAMERA_PARAMS : OBS_CAMERA_NONE;
}

obs_status obs__camera_resolve(const obs_gbuffer *gb, const obs_params *p, obs_camera *out,
                               char err[OBS_ERR_LEN])
{
    obs_camera cam = gb->camera;
    int dw = gb->display_width > 0 ? gb->display_width : gb->width;
    int dh = gb->display_height > 0 ? gb->display_height : gb->height;

    /* The vertical field of view: given, or from the horizontal one
     * (tan(fy/2) = tan(fx/2) h / w), or from focal length and horizontal
     * aperture (tan(fx/2) = aperture / (2 focal)). */
    double half_x = p->fov_x > 0.0f ? tan(p->fov_x * OBS__PI / 360.0)
                    : p->focal_length > 0.0f && p->aperture > 0.0f
                        ? p->aperture / (2.0 * p->focal_length)
                        : 0.0;
    float fov_y = p->fov_y > 0.0f ? p->fov_y
                  : half_x > 0.0 ? (float)(360.0 / OBS__PI * atan(half_x * dh / dw))
                                 : 0.0f;
    if (fov_y > 0.0f) {
        obs_camera fov;
        obs_camera_from_fov(fov_y, (float)dw / (float)dh, p->near, p->far, &fov);
        memcpy(cam.projection, fov.projection, sizeof cam.projection);
        cam.has_projection = 1;
        cam.source = OBS_CAMERA_PARAMS;
    }
    if (p->has_world_to_camera) {
        memcpy(cam.world_to_camera, p->world_to_camera, sizeof cam.world_to_camera);
        cam.has_world_to_camera = 1;
    }
    if (!cam.has_world_to_camera)
        obs__mat4_identity(cam.world_to_camera);
    if (!cam.has_projection)
        return obs__fail(err, OBS_NO_CAMERA,
                         "no camera: the G-buffer has no worldToCamera/worldToNDC header "
                         "attributes; give a camera JSON (--camera) or a field of view (--fov-y, "
                         "--fov-x, or --focal-length with --aperture)");
    *out = cam;
    return OBS_OK;
}

int obs_camera_of_run(const obs_gbuffer *gb, const obs_params *p, obs_camera *out)
{
    obs_params r;
    char err[OBS_ERR_LEN];
    obs_params_resolve(p, &r);
    return obs__camera_resolve(gb, &r, out, err) == OBS_OK;
}
