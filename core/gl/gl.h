/* Internal GL layer: the function table, the context struct, helpers.
 *
 * GL entry points are loaded through the backend's GetProcAddress into a
 * table, never linked directly: libOSMesa and libglvnd both export gl*
 * symbols, and only the loaded table is sure to reach the context that is
 * current.  Code calls glFoo(...) as usual; the macros below route the call
 * through the calling thread's current table. */
#ifndef OBSCURA_GL_H
#define OBSCURA_GL_H

#include <GL/glcorearb.h>

#include "gl/backend.h"
#include "gl/uniform.h"

#define OBS__GL_FUNCS(X)                                                       \
    X(PFNGLGETSTRINGPROC, GetString)                                           \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                                       \
    X(PFNGLGETERRORPROC, GetError)                                             \
    X(PFNGLENABLEPROC, Enable)                                                 \
    X(PFNGLDISABLEPROC, Disable)                                               \
    X(PFNGLFINISHPROC, Finish)                                                 \
    X(PFNGLVIEWPORTPROC, Viewport)                                             \
    X(PFNGLSCISSORPROC, Scissor)                                               \
    X(PFNGLCREATESHADERPROC, CreateShader)                                     \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                     \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                   \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                       \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                             \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                     \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                   \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                     \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                       \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                     \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                           \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                   \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                                         \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                         \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                                           \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                                           \
    X(PFNGLUNIFORM2IPROC, Uniform2i)                                           \
    X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                         \
    X(PFNGLUNIFORM2FVPROC, Uniform2fv)                                         \
    X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                         \
    X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv)                             \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                             \
    X(PFNGLGENTEXTURESPROC, GenTextures)                                       \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                 \
    X(PFNGLBINDTEXTUREPROC, BindTexture)                                       \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                   \
    X(PFNGLTEXSTORAGE2DPROC, TexStorage2D)                                     \
    X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                   \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                   \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                                       \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                               \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                         \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                               \
    X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                     \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                 \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                               \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                         \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                               \
    X(PFNGLDRAWARRAYSPROC, DrawArrays)                                         \
    X(PFNGLREADBUFFERPROC, ReadBuffer)                                         \
    X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                       \
    X(PFNGLREADPIXELSPROC, ReadPixels)                                         \
    X(PFNGLGENQUERIESPROC, GenQueries)                                         \
    X(PFNGLDELETEQUERIESPROC, DeleteQueries)                                   \
    X(PFNGLQUERYCOUNTERPROC, QueryCounter)                                     \
    X(PFNGLBEGINQUERYPROC, BeginQuery)                                         \
    X(PFNGLENDQUERYPROC, EndQuery)                                             \
    X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v)                       \
    /* meshes (raster_gl.c) */                                                 \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                                         \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                   \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                                         \
    X(PFNGLBUFFERDATAPROC, BufferData)                                         \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                       \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)               \
    X(PFNGLDRAWELEMENTSPROC, DrawElements)                                     \
    X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                   \
    /* deep input's node planes (deep_gl.c) */                                 \
    X(PFNGLTEXSTORAGE3DPROC, TexStorage3D)                                     \
    X(PFNGLTEXSUBIMAGE3DPROC, TexSubImage3D)                                   \
    /* the A-buffer rasteriser's linked lists (raster_deep_gl.c) */            \
    X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                 \
    X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                             \
    X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                                   \
    X(PFNGLGETTEXIMAGEPROC, GetTexImage)                                       \
    X(PFNGLBINDIMAGETEXTUREPROC, BindImageTexture)                             \
    /* the frame's uniform block, its layout as the tests read it */           \
    X(PFNGLGETPROGRAMRESOURCEINDEXPROC, GetProgramResourceIndex)               \
    X(PFNGLGETPROGRAMRESOURCEIVPROC, GetProgramResourceiv)                     \
    /* the program cache (progcache.c) */                                      \
    X(PFNGLPROGRAMBINARYPROC, ProgramBinary)                                   \
    X(PFNGLGETPROGRAMBINARYPROC, GetProgramBinary)                             \
    X(PFNGLPROGRAMPARAMETERIPROC, ProgramParameteri)

/* Optional entry points (may be NULL). */
#define OBS__GL_FUNCS_OPT(X) X(PFNGLDEBUGMESSAGECALLBACKPROC, DebugMessageCallback)

typedef struct obs__gl {
#define OBS__GL_FIELD(type, name) type name;
    OBS__GL_FUNCS(OBS__GL_FIELD)
    OBS__GL_FUNCS_OPT(OBS__GL_FIELD)
#undef OBS__GL_FIELD
} obs__gl;

/* The table of the context current on this thread. */
extern _Thread_local const obs__gl *obs__glp;

#define glGetString obs__glp->GetString
#define glGetIntegerv obs__glp->GetIntegerv
#define glGetError obs__glp->GetError
#define glEnable obs__glp->Enable
#define glDisable obs__glp->Disable
#define glFinish obs__glp->Finish
#define glViewport obs__glp->Viewport
#define glScissor obs__glp->Scissor
#define glCreateShader obs__glp->CreateShader
#define glShaderSource obs__glp->ShaderSource
#define glCompileShader obs__glp->CompileShader
#define glGetShaderiv obs__glp->GetShaderiv
#define glGetShaderInfoLog obs__glp->GetShaderInfoLog
#define glDeleteShader obs__glp->DeleteShader
#define glCreateProgram obs__glp->CreateProgram
#define glAttachShader obs__glp->AttachShader
#define glLinkProgram obs__glp->LinkProgram
#define glGetProgramiv obs__glp->GetProgramiv
#define glGetProgramInfoLog obs__glp->GetProgramInfoLog
#define glDeleteProgram obs__glp->DeleteProgram
#define glUseProgram obs__glp->UseProgram
#define glGetUniformLocation obs__glp->GetUniformLocation
#define glUniform1i obs__glp->Uniform1i
#define glUniform1f obs__glp->Uniform1f
#define glUniform2i obs__glp->Uniform2i
#define glUniform1fv obs__glp->Uniform1fv
#define glUniform2fv obs__glp->Uniform2fv
#define glUniform4fv obs__glp->Uniform4fv
#define glUniformMatrix3fv obs__glp->UniformMatrix3fv
#define glUniformMatrix4fv obs__glp->UniformMatrix4fv
#define glGenTextures obs__glp->GenTextures
#define glDeleteTextures obs__glp->DeleteTextures
#define glBindTexture obs__glp->BindTexture
#define glActiveTexture obs__glp->ActiveTexture
#define glTexStorage2D obs__glp->TexStorage2D
#define glTexSubImage2D obs__glp->TexSubImage2D
#define glTexParameteri obs__glp->TexParameteri
#define glPixelStorei obs__glp->PixelStorei
#define glGenFramebuffers obs__glp->GenFramebuffers
#define glDeleteFramebuffers obs__glp->DeleteFramebuffers
#define glBindFramebuffer obs__glp->BindFramebuffer
#define glFramebufferTexture2D obs__glp->FramebufferTexture2D
#define glCheckFramebufferStatus obs__glp->CheckFramebufferStatus
#define glGenVertexArrays obs__glp->GenVertexArrays
#define glDeleteVertexArrays obs__glp->DeleteVertexArrays
#define glBindVertexArray obs__glp->BindVertexArray
#define glDrawArrays obs__glp->DrawArrays
#define glReadBuffer obs__glp->ReadBuffer
#define glDrawBuffers obs__glp->DrawBuffers
#define glReadPixels obs__glp->ReadPixels
#define glGenQueries obs__glp->GenQueries
#define glDeleteQueries obs__glp->DeleteQueries
#define glQueryCounter obs__glp->QueryCounter
#define glBeginQuery obs__glp->BeginQuery
#define glEndQuery obs__glp->EndQuery
#define glGetQueryObjectui64v obs__glp->GetQueryObjectui64v
#define glGenBuffers obs__glp->GenBuffers
#define glDeleteBuffers obs__glp->DeleteBuffers
#define glBindBuffer obs__glp->BindBuffer
#define glBufferData obs__glp->BufferData
#define glVertexAttribPointer obs__glp->VertexAttribPointer
#define glEnableVertexAttribArray obs__glp->EnableVertexAttribArray
#define glDrawElements obs__glp->DrawElements
#define glClearBufferfv obs__glp->ClearBufferfv
#define glTexStorage3D obs__glp->TexStorage3D
#define glTexSubImage3D obs__glp->TexSubImage3D
#define glBindBufferBase obs__glp->BindBufferBase
#define glGetBufferSubData obs__glp->GetBufferSubData
#define glMemoryBarrier obs__glp->MemoryBarrier
#define glGetTexImage obs__glp->GetTexImage
#define glBindImageTexture obs__glp->BindImageTexture
#define glGetProgramResourceIndex obs__glp->GetProgramResourceIndex
#define glGetProgramResourceiv obs__glp->GetProgramResourceiv
#define glProgramBinary obs__glp->ProgramBinary
#define glGetProgramBinary obs__glp->GetProgramBinary
#define glProgramParameteri obs__glp->ProgramParameteri

/* Loads every entry point; fails naming the first one missing. */
obs_status obs__gl_load(obs__gl *gl, obs__getproc_fn getproc, char err[OBS_ERR_LEN]);

/* Compiles and links a program from a vertex and a fragment source (the
 * fragment source is the concatenation of `frag_parts`).  A compile or
 * link failure is OBS_GL_SHADER with the shader's name and info log.
 * With a program cache on the current context (progcache.h) the program
 * is loaded from it when there, and stored in it when built. */
obs_status obs__gl_program(const char *name, const char *vert, const char *const *frag_parts,
                           int frag_count, GLuint *out, char err[OBS_ERR_LEN]);

/* Deletes the programs of p[0..n) that were built (0: never built). */
void obs__gl_delete_programs(const GLuint *p, size_t n);
#define OBS__GL_DELETE_PROGRAMS(a) obs__gl_delete_programs((a), sizeof(a) / sizeof((a)[0]))

/* Sets the uniforms of the list u (ending at a NULL name) of the program
 * in use, reading their values from the struct at base. */
void obs__gl_set_uniforms(GLuint prog, const void *base, const obs__uniform *u);

/* Drains glGetError; returns OBS_GL_ERROR naming `where` if any. */
obs_status obs__gl_check(const char *where, char err[OBS_ERR_LEN]);

/* ---- one context of one backend (device.c) ------------------------------ */

#define OBS__CACHE_PATH_LEN 4096

typedef struct obs__progcache {
    char dir[OBS__CACHE_PATH_LEN]; /* the cache's root; "" : no cache */
    int writable;                  /* 0: entries are loaded, none is stored */
    int formats;                   /* GL_NUM_PROGRAM_BINARY_FORMATS of the context */
    const char *vendor, *renderer, *version; /* the device's strings */
    unsigned long compiled;        /* programs built from source */
    unsigned long loaded;          /* programs loaded from the cache */
    unsigned long rejected;        /* entries found but unusable (rebuilt) */
    int store_warned;              /* one warning for failed writes */
    obs_log_fn log;
    void *log_user;
} obs__progcache;

/* The cache of the context current on this thread (defined and set by
 * device.c with the function table); NULL when none is current.  The
 * state is the device's; the code that fills and reads it is
 * progcache.c (progcache.h), which sits above the device. */
extern _Thread_local obs__progcache *obs__progcache_cur;


typedef struct obs__gl_device {
    obs_backend backend;
    obs__backend_state st;
    obs__gl gl;
    int debug;            /* install the KHR_debug callback */
    obs_log_fn log;       /* where the callback and backend probing report */
    void *log_user;
    char version[128], vendor[128], renderer[256];
    GLuint vao;           /* empty vertex array for the full-screen triangle */
    obs__progcache cache; /* the program cache and the build counters */
} obs__gl_device;

/* Creates the context of `backend` (AUTO: the first of EGL device, EGL
 * surfaceless, OSMesa that works, the others' failures logged at debug
 * level), loads its table and leaves it current.  debug, log and
 * log_user are read from *d; the rest is filled, d->cache but for its
 * counters (the caller opens it before, attaches it after:
 * progcache.h). */
obs_status obs__gl_device_create(obs__gl_device *d, obs_backend backend, char err[OBS_ERR_LEN]);

/* Makes the context current on the calling thread (and its table). */
obs_status obs__gl_device_bind(obs__gl_device *d, char err[OBS_ERR_LEN]);

/* Deletes what create made and the context itself. */
void obs__gl_device_destroy(obs__gl_device *d);

#endif
