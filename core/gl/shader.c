/* Shader programs: compile and link, failures carry the info log. */
#include <stdio.h>
#include <string.h>

#include "gl/gl.h"
#include "gl/progcache.h"

static obs_status compile(const char *name, GLenum type, const char *const *parts, int count,
                          GLuint *out, char err[OBS_ERR_LEN])
{
    GLuint sh = glCreateShader(type);
    GLint ok = 0;
    glShaderSource(sh, count, parts, NULL);
    glCompileShader(sh);
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[OBS_ERR_LEN - 64] = "";
        glGetShaderInfoLog(sh, (GLsizei)sizeof log, NULL, log);
        glDeleteShader(sh);
        return obs__fail(err, OBS_GL_SHADER, "shader %s (%s) failed to compile: %s", name,
                         type == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
    }
    *out = sh;
    return OBS_OK;
}

obs_status obs__gl_program(const char *name, const char *vert, const char *const *frag_parts,
                           int frag_count, GLuint *out, char err[OBS_ERR_LEN])
{
    GLuint vs = 0, fs = 0, prog = 0;
    GLint ok = 0;
    obs__progcache *pc = obs__progcache_cur;
    obs__progkey key = {0};
    int cached = pc && pc->dir[0] && pc->formats &&
                 obs__progkey_make(pc, vert, frag_parts, frag_count, &key) == 0;
    if (cached && obs__progcache_load(pc, &key, out)) {
        obs__progkey_free(&key);
        return OBS_OK;
    }
    obs_status s = compile(name, GL_VERTEX_SHADER, &vert, 1, &vs, err);
    if (s != OBS_OK)
        goto fail;
    s = compile(name, GL_FRAGMENT_SHADER, frag_parts, frag_count, &fs, err);
    if (s != OBS_OK)
        goto fail;
    prog = glCreateProgram();
    glAttachShader(prog, vs);
    glAttachShader(prog, fs);
    if (cached) /* asked before linking, so that the binary can be read back */
        glProgramParameteri(prog, GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
    glLinkProgram(prog);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[OBS_ERR_LEN - 64] = "";
        glGetProgramInfoLog(prog, (GLsizei)sizeof log, NULL, log);
        s = obs__fail(err, OBS_GL_SHADER, "program %s failed to link: %s", name, log);
        glDeleteProgram(prog);
        goto fail;
    }
    *out = prog;
    if (pc)
        pc->compiled++;
    if (cached)
        obs__progcache_store(pc, &key, prog);
fail:
    obs__progkey_free(&key);
    if (vs)
        glDeleteShader(vs);
    if (fs)
        glDeleteShader(fs);
    return s;
}

void obs__gl_delete_programs(const GLuint *p, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (p[k])
            glDeleteProgram(p[k]);
}

obs_status obs__gl_check(const char *where, char err[OBS_ERR_LEN])
{
    GLenum e, first = GL_NO_ERROR;
    while ((e = glGetError()) != GL_NO_ERROR)
        if (first == GL_NO_ERROR)
            first = e;
    if (first == GL_NO_ERROR)
        return OBS_OK;
    return obs__fail(err, OBS_GL_ERROR, "OpenGL error 0x%04x in %s", (unsigned)first, where);
}

void obs__gl_set_uniforms(GLuint prog, const void *base, const obs__uniform *u)
{
    for (; u->name; u++) {
        const char *v = (const char *)base + u->offset;
        GLint loc = glGetUniformLocation(prog, u->name);
        GLsizei n = u->count_of ? *(const int *)((const char *)base + u->count_of) * u->scale : 1;
        switch (u->type) {
        case OBS__U_INT: glUniform1i(loc, *(const int *)v); break;
        case OBS__U_FLOAT:
            if (u->count_of)
                glUniform1fv(loc, n, (const float *)v);
            else
                glUniform1f(loc, *(const float *)v);
            break;
        case OBS__U_VEC2: glUniform2fv(loc, n, (const float *)v); break;
        }
    }
}
