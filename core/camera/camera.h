/* The camera of a frame, decided in one place (core/camera/):
 *   exr.c      the EXR header's conventions, read (standard or Arnold NDC,
 *              V-Ray, lens) and written (worldToCamera/worldToNDC);
 *   json.c     a camera JSON (obs_camera_read_json);
 *   request.c  a request's parameters and wire matrices, and the camera a
 *              frame runs with (obs__camera_resolve, core/internal.h);
 *   solve.c    the camera solved from a position pass, and the camera
 *              checked against it.
 * Readers hand over what they found and take back one camera with its
 * source; writers take the attributes from obs__camera_exr_attrs. */
#ifndef OBS_CAMERA_CAMERA_H
#define OBS_CAMERA_CAMERA_H

#include <stddef.h>

#include <openexr.h>

#include "obscura/io.h"

/* The camera of part `part` from every header attribute that describes
 * one (exr.c); `renderer` is the detected preset (may be NULL).  With an
 * `info`, its camera_source, camera_check, camera_clip, camera_arnold
 * are set and the camera's warnings appended to its warnings. */
void obs__camera_read_header(exr_const_context_t ctx, int part, const char *renderer,
                             obs_camera *cam, obs_exr_info *info);

/* obs__camera_read_header() with no renderer and no info (the deep
 * reader, core/io/exr_deep.c). */
void obs__exr_read_camera(exr_const_context_t ctx, int part, obs_camera *cam);

/* The header attributes that carry a camera, in the writer's order
 * (exr.c): worldToCamera, then worldToNDC with a projection; none without
 * a world_to_camera.  Returns how many; `attrs` may be NULL to ask only
 * that.  The first's name is OBS__CAMERA_ATTR_WTC (a source that has it
 * keeps its own camera). */
#define OBS__CAMERA_ATTRS 2
#define OBS__CAMERA_ATTR_WTC "worldToCamera"
typedef struct obs__camera_attr {
    const char *name;
    float m[16]; /* row-major, OpenEXR's row-vector convention */
} obs__camera_attr;
int obs__camera_exr_attrs(const obs_camera *cam, obs__camera_attr attrs[OBS__CAMERA_ATTRS]);

/* The worldToCamera and worldToNDC attributes (row-major, OpenEXR's
 * row-vector convention, the standard's NDC) of a camera: the exact
 * inverse of the header reader's mapping (exr.c); the deep writer
 * (core/io/exr_deep_write.cpp, C++) declares it itself. */
void obs__exr_camera_matrices(const obs_camera *cam, float wtc[16], float ndc[16]);

/* The camera `p` gives `gb` checked against its position pass (solve.c):
 * 1 with the disagreement in `msg` when the reprojection error is too
 * large, 0 when it agrees or cannot be checked. */
int obs__camera_check_position(const obs_gbuffer *gb, const obs_params *p, char *msg,
                               size_t len);

#endif
