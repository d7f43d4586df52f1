/* The bent normal's result image (OBS_OUTPUT_BENT), after the readback on
 * every device: the method's view-space sum (GL: the AO pass's fifth
 * attachment; CPU: obs__method_pixel_bent) normalised and turned into the
 * normals' space, the inverse of the prep pass's normal matrix (a
 * rotation: its transpose), so it lines up with the input's normals. */
#include <math.h>

#include "chain/passes.h"

void obs__bent_finish(const obs__plan *pl, obs_result *out)
{
    if (!out->bent.data)
        return;
    const float *M = pl->f.normal_matrix; /* input normal -> view, row-major */
    size_t n = (size_t)out->bent.width * out->bent.height;
    for (size_t i = 0; i < n; i++) {
        float *b = out->bent.data + 3 * i, w[3];
        for (int r = 0; r < 3; r++)
            w[r] = M[r] * b[0] + M[3 + r] * b[1] + M[6 + r] * b[2]; /* M^T b */
        float l = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        for (int k = 0; k < 3; k++)
            b[k] = l > 0.0f ? w[k] / l : 0.0f;
    }
}
