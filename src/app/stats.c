/* stats.c: the --stats JSON file. */
#include "app/stats.h"

#include <math.h>

#include "core/fileio.h"

void ps_stats_add(ps_run_stats *s, const char *key, double value)
{
    if (s->extra_count >= PS_STATS_MAX_EXTRA)
        return;
    s->extra[s->extra_count].key = key;
    s->extra[s->extra_count].value = value;
    s->extra_count++;
}

void ps_json_string(FILE *f, const char *text)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
        if (*p == '"' || *p == '\\')
            fprintf(f, "\\%c", *p);
        else if (*p < 0x20)
            fprintf(f, "\\u%04x", *p);
        else
            fputc(*p, f);
    }
    fputc('"', f);
}

/* JSON has no inf or NaN; a rate over zero seconds is reported as 0. */
static double finite_or_zero(double v) { return isfinite(v) ? v : 0.0; }

static double rate(double count, double seconds) { return seconds > 0.0 ? count / seconds : 0.0; }

void ps_stats_print(FILE *f, const ps_run_stats *s)
{
    uint64_t emitted = s->emitted[PS_MAP_CAUSTIC] + s->emitted[PS_MAP_GLOBAL];
    fprintf(f, "{\n");
    fprintf(f, "  \"emitted_caustic\": %llu,\n", (unsigned long long)s->emitted[PS_MAP_CAUSTIC]);
    fprintf(f, "  \"emitted_global\": %llu,\n", (unsigned long long)s->emitted[PS_MAP_GLOBAL]);
    fprintf(f, "  \"stored_caustic\": %llu,\n", (unsigned long long)s->stored[PS_MAP_CAUSTIC]);
    fprintf(f, "  \"stored_global\": %llu,\n", (unsigned long long)s->stored[PS_MAP_GLOBAL]);
    fprintf(f, "  \"trace_seconds\": %.6g,\n", finite_or_zero(s->trace_seconds));
    fprintf(f, "  \"splat_seconds\": %.6g,\n", finite_or_zero(s->splat_seconds));
    fprintf(f, "  \"frames\": %llu,\n", (unsigned long long)s->frames);
    fprintf(f, "  \"photons_per_second\": %.6g,\n", finite_or_zero(rate((double)emitted, s->trace_seconds)));
    fprintf(f, "  \"rays_traced\": %llu,\n", (unsigned long long)s->rays);
    fprintf(f, "  \"rays_per_second\": %.6g,\n", finite_or_zero(rate((double)s->rays, s->ray_seconds > 0.0 ? s->ray_seconds : s->trace_seconds)));
    for (size_t k = 0; k < s->extra_count; k++) {
        fprintf(f, "  ");
        ps_json_string(f, s->extra[k].key);
        fprintf(f, ": %.10g,\n", finite_or_zero(s->extra[k].value));
    }
    fprintf(f, "  \"skipped\": [");
    for (size_t k = 0; k < s->skip_count; k++) {
        fprintf(f, "%s\n    {\"pass\": ", k ? "," : "");
        ps_json_string(f, s->skips[k].pass);
        fprintf(f, ", \"reason\": ");
        ps_json_string(f, s->skips[k].reason);
        fprintf(f, "}");
    }
    fprintf(f, "%s]\n}\n", s->skip_count ? "\n  " : "");
}

ps_status ps_stats_write(const char *path, const ps_run_stats *s, ps_error *err)
{
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err ? err->status : PS_ERR_IO;
    ps_stats_print(ps_outfile_stream(out), s);
    return ps_outfile_commit(out, err);
}
