/* stats.h: the --stats JSON file every program writes (contract, "--stats JSON").
 *
 * The contract's keys always appear; programs add their own after them. The
 * file is written whole or not at all (ps_outfile). */
#ifndef PS_APP_STATS_H
#define PS_APP_STATS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core/status.h"
#include "photon/tracer.h"

#define PS_STATS_MAX_EXTRA 48

typedef struct ps_run_stats {
    uint64_t emitted[PS_MAP_COUNT], stored[PS_MAP_COUNT];
    double trace_seconds, splat_seconds;
    uint64_t frames;
    uint64_t rays;
    double ray_seconds; /* the time those rays took (0: trace_seconds) */
    const ps_skip *skips;
    size_t skip_count;
    /* Further numeric keys, e.g. {"threads", 2}. */
    struct {
        const char *key;
        double value;
    } extra[PS_STATS_MAX_EXTRA];
    size_t extra_count;
} ps_run_stats;

/* Appends a key to s->extra (silently ignored beyond PS_STATS_MAX_EXTRA). */
void ps_stats_add(ps_run_stats *s, const char *key, double value);

/* Writes s as one JSON object to f. */
void ps_stats_print(FILE *f, const ps_run_stats *s);

/* Writes s to path atomically. */
ps_status ps_stats_write(const char *path, const ps_run_stats *s, ps_error *err);

/* Writes a JSON string literal (quoted, escaped). */
void ps_json_string(FILE *f, const char *text);

#endif
