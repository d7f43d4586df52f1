/* The full-screen triangle against a deadline (draw.h). */
#include "draw.h"
#include "internal.h"

obs_status obs__gl_draw_banded(GLuint vao, int w, int h, double t0_ms, double limit_ms,
                               const char *pass, char err[OBS_ERR_LEN])
{
    glViewport(0, 0, w, h);
    glBindVertexArray(vao);
    if (limit_ms <= 0.0) {
        glDrawArrays(GL_TRIANGLES, 0, 3);
        return OBS_OK;
    }
    const int rows = (h + OBS__DEADLINE_BANDS - 1) / OBS__DEADLINE_BANDS;
    const int bands = (h + rows - 1) / rows;
    /* The scissor clips the rasterised fragments only: each pixel is
     * shaded exactly as by the whole draw. */
    glEnable(GL_SCISSOR_TEST);
    for (int b = 0; b < bands; b++) {
        const int y = b * rows;
        glScissor(0, y, w, y + rows > h ? h - y : rows);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glFinish();
        const double took = obs__now_ms() - t0_ms;
        if (took > limit_ms && b + 1 < bands) {
            glDisable(GL_SCISSOR_TEST);
            return obs__fail(err, OBS_DEADLINE,
                             "the frame's GL work ran past its deadline of %.3g s: the %s pass "
                             "was stopped after %d of %d bands of rows, %.3g s in; lower the "
                             "samples or the size",
                             limit_ms / 1e3, pass, b + 1, bands, took / 1e3);
        }
    }
    glDisable(GL_SCISSOR_TEST);
    return OBS_OK;
}
