/* The CPU chain in bands of rows (bands_run.c): a frame whose planes
 * would take more than the memory budget runs band by band, each band's
 * planes holding its rows and the halo its samples read; the same bytes
 * as the whole frame.  No GL.  Not installed. */
#ifndef OBSCURA_BANDS_RUN_H
#define OBSCURA_BANDS_RUN_H

#include "chain/passes_cpu.h"

/* Frames under this many rows run whole; bands are not cut smaller. */
#define OBS__BANDS_MIN_HEIGHT 64
#define OBS__BANDS_MIN_ROWS 16
/* obs_run_cpu_rows reads the depth this many rows at a time for the
 * rows' reach, before the bands. */
#define OBS__BANDS_REACH_ROWS 256


/* The rows of the first try at a band for c's plan (c->pl set, its rows
 * not): opt->band_rows when set, else 0 (the whole frame) when its planes
 * fit the budget, else a count from the budget. */
int obs__bands_rows(obs__cpu_run *c, const obs_cpu_options *opt);

/* Runs c's plan (pl, which each band's half-size mask planes are set
 * in) band by band into c->out (allocated, whole): bands of
 * `rows` rows, each shrunk (halved, down to OBS__BANDS_MIN_ROWS) until
 * its planes fit the budget unless opt->band_rows forces the count;
 * each band said through opt->log.  With t, the passes' times summed. */
obs_status obs__bands_run(obs__cpu_run *c, obs__plan *pl, int rows, const obs_cpu_options *opt,
                          obs_pass_times *t, char err[OBS_ERR_LEN]);

#endif
