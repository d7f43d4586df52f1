/* The bent normal of the VAO estimator (OBS_OUTPUT_BENT, methods vaopp
 * and vao).  VAO's tangent sphere of radius R/2 touching p stands for
 * the cosine-weighted hemisphere (its chord from p along a direction at
 * angle theta to n has length R cos theta); the mean unoccluded direction
 * is taken as the direction from p to the centroid of the sphere's open
 * volume (the estimator's own measure: a direction's cone of the sphere
 * moves the centroid by cos^4 theta, not cos theta, so grazing openings
 * count less than in a ray tracer's cosine-weighted bent normal).  Each line sample's pipe (eq 1) has its open part at the near
 * end, dz long, so its centroid is the sample's disk point moved along
 * view Z to the middle of that part; the volume centroid is the
 * dz-weighted mean of those, and the bent normal is
 *   b = sum_i dz_i (m_i - p),  m_i = (disk_i, c.z + h_i - dz_i / 2),
 * normalised by the caller (the sphere's centre, so n, when nothing
 * occludes).  GLSL twin: vao_bent_sample() in vao.glsl. */
#include "chain/frame.h"

void obs__vao_bent_sample(const float c[3], float r, const float rot[2], float sx, float sy, float h,
                          float dz, const float p[3], float bent[3])
{
    /* the disk point of obs__disk_map / disk_point(): c.xy + r rot(sx, sy) */
    float mx = c[0] + r * (rot[0] * sx - rot[1] * sy);
    float my = c[1] + r * (rot[1] * sx + rot[0] * sy);
    float mz = c[2] + h - 0.5f * dz;
    bent[0] += dz * (mx - p[0]);
    bent[1] += dz * (my - p[1]);
    bent[2] += dz * (mz - p[2]);
}
