/* obscura's program cache: linked programs kept on disk as the driver's
 * program binaries (glGetProgramBinary / glProgramBinary), so that a
 * fresh process loads them instead of compiling.  Not installed.
 *
 * An entry is one file DIR/programs/HASH.bin, HASH the SHA-256 (nettle)
 * of its key: the vendor, renderer and version strings of the driver, the
 * vertex source and the concatenated fragment source (every define
 * included).  The entry stores the key in full and a SHA-256 of key and
 * binary: a file whose key differs from the one asked for (another
 * driver, a hash collision), whose digest or size does not match
 * (corrupt, truncated) or whose binary the driver refuses is ignored,
 * counted in `rejected`, and rebuilt.  Entries are written to a temporary
 * file in the same folder and renamed over the old name, so a reader sees
 * a whole entry or none.
 *
 * Mesa offers program binaries only while its own shader cache is on, and
 * llvmpipe keeps the machine code it generates at the first draw only
 * there; so the cache also points Mesa's shader cache at DIR
 * (MESA_SHADER_CACHE_DIR, unless set) and turns it on for this process. */
#ifndef OBSCURA_GL_PROGCACHE_H
#define OBSCURA_GL_PROGCACHE_H

#include <GL/glcorearb.h>

#include "gl/gl.h"

/* obs__progcache, the cache's state, is a member of the device (gl.h). */

/* Opens the cache at root (NULL or "": none) before the context is made:
 * creates root/programs, checks that it can be written (else read-only,
 * or no cache when it cannot be read either: one log line says which and
 * why), and points Mesa's shader cache at root.  log/user are where it
 * reports. */
void obs__progcache_open(obs__progcache *pc, const char *root, obs_log_fn log, void *user);

/* After the context exists and is current: the driver's strings (kept
 * by pointer: they live as long as pc) and its binary formats. */
void obs__progcache_attach(obs__progcache *pc, const char *vendor, const char *renderer,
                           const char *version);

/* One program's key. */
typedef struct obs__progkey {
    unsigned char *bytes;
    size_t len;
    char name[2 * 32 + 1]; /* hex SHA-256 of bytes */
} obs__progkey;

/* Makes the key of (vert, frag_parts); 0, or -1 when out of memory.
 * Free with obs__progkey_free. */
int obs__progkey_make(const obs__progcache *pc, const char *vert, const char *const *frag_parts,
                      int frag_count, obs__progkey *key);
void obs__progkey_free(obs__progkey *key);

/* Loads the entry of key into a new program object; 1 and *out set when
 * it linked, else 0 (nothing left behind; an entry that was there but
 * could not be used is counted in `rejected`). */
int obs__progcache_load(obs__progcache *pc, const obs__progkey *key, GLuint *out);

/* Stores the linked program prog under key (when the cache is writable);
 * a failure is logged once and otherwise ignored. */
void obs__progcache_store(obs__progcache *pc, const obs__progkey *key, GLuint prog);

/* The path of key's entry in buf (the tests damage entries). */
void obs__progcache_entry_path(const obs__progcache *pc, const obs__progkey *key, char *buf,
                               size_t n);

#endif
