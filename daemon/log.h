/* obscurad's log: one line per call on stderr, filtered by level. */
#ifndef OBSD_LOG_H
#define OBSD_LOG_H

#include "obscura/obscura.h"

void obsd_log_set_level(int level); /* OBSD_LOG_* of config.h */
int obsd_log_enabled(int level);
void obsd_log(int level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The core's log callback (obs_log_fn) into the same log. */
void obsd_log_core(void *user, obs_log_level level, const char *msg);

#endif
