/* machine.c: what photosplat-bench measures of its machine (machine.h). */
/* MAP_ANONYMOUS and MADV_HUGEPAGE are Linux's, past POSIX. */
#define _GNU_SOURCE
#include "app/machine.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#ifdef __linux__
#include <sys/mman.h>
#endif

#include "core/clock.h"
#include "core/memory.h"
#include "photon/photon_map.h"
#include "photon/tracer.h"
#include "photon/world.h"
#include "scene/scene.h"

#define SMALL_PAGE ((size_t)4096)
#define BYTES_PER_MIB (1024.0 * 1024.0)

/* "model name : AMD EPYC" from /proc/cpuinfo, into cpu ("" when not there). */
static void read_cpu(char *cpu, size_t size)
{
    cpu[0] = '\0';
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        const char *colon = strchr(line, ':');
        if (strncmp(line, "model name", 10) != 0 || !colon)
            continue;
        colon++;
        while (*colon == ' ' || *colon == '\t')
            colon++;
        snprintf(cpu, size, "%s", colon);
        cpu[strcspn(cpu, "\n")] = '\0';
        break;
    }
    fclose(f);
}

static double read_load(void)
{
    double load = -1.0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &load) != 1)
            load = -1.0;
        fclose(f);
    }
    return load;
}

#if defined(__linux__) && defined(MADV_HUGEPAGE) && defined(MADV_NOHUGEPAGE)
/* Seconds to write one byte in each small page of `bytes` (a whole number of
 * large pages) of new anonymous memory, advised for large pages or against
 * them; < 0 when it could not be mapped. Aligned to a large page, so that
 * the kernel may back each with one. */
static double first_writes(size_t bytes, bool large)
{
    size_t span = bytes + PS_MEMORY_LARGE_PAGE;
    char *map = mmap(NULL, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (map == MAP_FAILED)
        return -1.0;
    volatile char *p = (char *)(((uintptr_t)map + PS_MEMORY_LARGE_PAGE - 1) & ~(uintptr_t)(PS_MEMORY_LARGE_PAGE - 1));
    (void)madvise((void *)p, bytes, large ? MADV_HUGEPAGE : MADV_NOHUGEPAGE); /* advice only */
    double t0 = ps_now_seconds();
    for (size_t i = 0; i < bytes; i += SMALL_PAGE)
        p[i] = 1;
    double t = ps_now_seconds() - t0;
    munmap(map, span);
    return t;
}
#endif

/* Photon paths a second of the scene's global map on one thread, the best of
 * PS_MACHINE_REPEATS. */
static ps_status trace_rate(const char *scene_path, double *rate, ps_error *err)
{
    ps_scene *scene = NULL;
    ps_world *world = NULL;
    ps_tracer *tracer = NULL;
    ps_status st = ps_scene_load(scene_path, NULL, &scene, err);
    if (st == PS_OK)
        st = ps_world_create(scene, NULL, &world, err);
    ps_tracer_options opt = ps_tracer_default_options();
    opt.threads = 1;
    if (st == PS_OK)
        st = ps_tracer_create(world, &opt, &tracer, err);
    double best = 0.0;
    for (int k = 0; k < PS_MACHINE_REPEATS && st == PS_OK; k++) {
        ps_photon_map m;
        ps_photon_map_init(&m, PS_MAP_GLOBAL);
        double t0 = ps_now_seconds();
        st = ps_tracer_trace(tracer, PS_MAP_GLOBAL, 0, PS_MACHINE_PATHS, PS_MACHINE_PATHS, &m, err);
        double t = ps_now_seconds() - t0;
        ps_photon_map_free(&m);
        if (st == PS_OK && t > 0.0 && PS_MACHINE_PATHS / t > best)
            best = PS_MACHINE_PATHS / t;
    }
    ps_tracer_destroy(tracer);
    ps_world_destroy(world);
    ps_scene_destroy(scene);
    *rate = best;
    return st;
}

ps_status ps_machine_measure(const char *scene_path, ps_machine *out, ps_error *err)
{
    memset(out, 0, sizeof *out);
    read_cpu(out->cpu, sizeof out->cpu);
    out->cores = ps_online_cores(); /* the tracer's own count: it is the tracer's cores that matter */
    out->load = read_load();
#if defined(__linux__) && defined(MADV_HUGEPAGE) && defined(MADV_NOHUGEPAGE)
    /* Memory first: what this process frees, the kernel would hand back to
     * it written already (0.12 ms a 2 MiB page against 3.0-3.4 here). */
    double large = first_writes(PS_MACHINE_FRESH_BYTES, true);
    if (large >= 0.0)
        out->fresh_ms_per_mib = 1e3 * large / ((double)PS_MACHINE_FRESH_BYTES / BYTES_PER_MIB);
    double small = first_writes(PS_MACHINE_FAULT_BYTES, false);
    if (small >= 0.0)
        out->fault_us = 1e6 * small / (double)(PS_MACHINE_FAULT_BYTES / SMALL_PAGE);
#endif
    return trace_rate(scene_path, &out->paths_per_second, err);
}

void ps_machine_describe(const ps_machine *m, const char *scene_name, char *buf, size_t size)
{
    char cores[32] = "", load[32] = "", memory[160] = "";
    if (m->cores > 0)
        snprintf(cores, sizeof cores, ", %ld cores", m->cores);
    if (m->load >= 0.0)
        snprintf(load, sizeof load, ", load %.2f", m->load);
    if (m->fresh_ms_per_mib > 0.0 && m->fault_us > 0.0)
        snprintf(memory, sizeof memory,
                 "; first writes to new memory cost %.2f ms a MiB (2 MiB pages), %.1f us a 4 KiB page",
                 m->fresh_ms_per_mib, m->fault_us);
    snprintf(buf, size, "%s%s%s; one core traces %.2f M photon paths a second (%s)%s",
             m->cpu[0] ? m->cpu : "processor unknown", cores, load, m->paths_per_second / 1e6, scene_name, memory);
}
