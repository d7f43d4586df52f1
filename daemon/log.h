/* obscurad's log: one line per call on stderr, filtered by level. */
#ifndef OBSD_LOG_H
#define OBSD_LOG_H

#include <stddef.h>

#include "obscura/obscura.h"

void obsd_log_set_level(int level); /* OBSD_LOG_* of config.h */
int obsd_log_enabled(int level);
void obsd_log(int level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* `n` bytes of `in` into out (at most cap - 1 and a '\0'), control
 * characters as \xNN; returns the length.  obsd_log does this to every
 * line's text. */
size_t obsd_log_escape(const char *in, size_t n, char *out, size_t cap);
/* The core's log callback (obs_log_fn) into the same log. */
void obsd_log_core(void *user, obs_log_level level, const char *msg);

#endif
