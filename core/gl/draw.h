/* The full-screen triangle, drawn at once or in bands of rows against a
 * deadline.  Not installed. */
#ifndef OBSCURA_GL_DRAW_H
#define OBSCURA_GL_DRAW_H

#include "gl.h"

/* Bands a pass is cut into when the frame has a deadline: it stops at
 * most one band (1/16 of the pass) past it. */
#define OBS__DEADLINE_BANDS 16

/* Draws the full-screen triangle of vertex array vao over the viewport
 * w x h of the bound framebuffer.  With limit_ms > 0, in bands of rows
 * (scissored), each finished (glFinish) before the clock (obs__now_ms) is
 * compared with t0_ms + limit_ms.  OBS_DEADLINE, naming `pass` and how
 * far it got, when a band ends past it and bands are left; the pass's
 * output is then incomplete. */
obs_status obs__gl_draw_banded(GLuint vao, int w, int h, double t0_ms, double limit_ms,
                               const char *pass, char err[OBS_ERR_LEN]);

#endif
