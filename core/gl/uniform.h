/* A uniform described as data: where its value lies in a C struct, so
 * that a table (core/methods/methods.c) can list a shader's uniforms
 * without GL code and obs__gl_set_uniforms (gl/shader.c) sets them.  No
 * GL headers here.  Not installed. */
#ifndef OBSCURA_GL_UNIFORM_H
#define OBSCURA_GL_UNIFORM_H

#include <stddef.h>

typedef enum obs__uniform_type {
    OBS__U_INT,   /* glUniform1i */
    OBS__U_FLOAT, /* glUniform1f, or 1fv for an array */
    OBS__U_VEC2   /* glUniform2fv */
} obs__uniform_type;

/* The value lies at base + offset; an array has its element count in the
 * int at base + count_of, times scale (3 for vec3s kept as floats);
 * count_of 0: one element. */
typedef struct obs__uniform {
    const char *name; /* NULL ends a list */
    obs__uniform_type type;
    size_t offset;
    size_t count_of;
    int scale;
} obs__uniform;

#endif
