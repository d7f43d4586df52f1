/* Deep input's GL objects kept in the context between frames (deep_gl.c;
 * torn down by deep_targets_gl.c).
 * Not installed. */
#ifndef OBSCURA_DEEP_TARGETS_GL_H
#define OBSCURA_DEEP_TARGETS_GL_H

#include "gl/gl.h"

#define OBS__DEEP_VARIANTS 256 /* 8 switches of the deep pass (deep_gl.c: DEEP_*) */

/* The deep pass's programs, and the node planes and the output target of
 * one size and node count. */
typedef struct obs__deep_targets {
    GLuint prog[OBS__DEEP_VARIANTS]; /* by variant (deep_gl.c: DEEP_*), built on first use, kept */
    int width, height, m;        /* 0: none allocated yet */
    unsigned long long bytes;    /* the textures' storage (obs_ctx_kept_bytes) */
    GLuint tex_pos, tex_nrm;     /* 2D arrays of m layers (RGBA32F) */
    GLuint tex_end;              /* 2D array of m layers (R32F): the nodes' intervals */
    GLuint tex_mask;             /* 2D array of m layers (RG32F): the nodes' object masks */
    GLuint tex_nodes;            /* 2D array of m layers (R32F): every node's AO (deep AO out) */
    /* RG32F (AO, the front node's planar depth, for the blur): the front
     * node's AO, the blend, and the blur's intermediate; fbo writes the
     * first two (the deep pass), the others one each (the blur) */
    GLuint tex_front, tex_blend, tex_tmp;
    GLuint fbo, fbo_front, fbo_blend, fbo_tmp;
} obs__deep_targets;

/* Deletes the programs, textures and framebuffer; the context is current.
 * With programs 0 the programs stay. */
void obs__deep_release(obs__deep_targets *t, int programs);

#endif
