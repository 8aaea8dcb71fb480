/* bench_main.c: photosplat-bench, run time against error. For each bench
 * scene: converged references per component from photosplat-ref (cached by
 * a hash of the scene, its meshes, the renderer and its settings), then
 * photosplat-snap runs that write checkpoints at increasing times for each
 * splat mode, buffer precision and radius schedule, each checkpoint's
 * layers compared with photosplat-compare against the references. Writes a
 * CSV, a Markdown table and gnuplot plots to bench/results/.
 *
 * It drives the programs as a user would (one process each), so what it
 * measures includes everything a snapshot costs; the seconds it reports are
 * snap's own clock from start to the checkpoint's frame. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "app/cli.h"
#include "app/machine.h"
#include "app/options.h"
#include "core/fileio.h"
#include "image/image.h"
#include "scene/scene.h"

#define PROG "photosplat-bench"

static const char usage[] =
    "usage: " PROG " [options]\n"
    "\n"
    "Measures the preview's error against run time. For each scene: converged\n"
    "references per component (photosplat-ref, cached until the scene or the\n"
    "renderer changes), photosplat-snap checkpoints at increasing times for each\n"
    "splat mode, colour buffer and radius schedule, and the error of each\n"
    "checkpoint's layers (direct, caustic, global, specular) and whole image against the\n"
    "references (photosplat-compare relMSE, both clamped to what the display\n"
    "shows at the scene's exposure). Writes to the output folder:\n"
    "  bench.csv      every measurement\n"
    "  bench.md       tables: error at each time, per scene and configuration\n"
    "  bench.png      the main plot: whole-image error against seconds, per scene\n"
    "  bench-photons.png  the same against photons emitted\n"
    "  SCENE.png      per scene: each layer's error against seconds\n"
    "  data/*.dat     the plotted data (gnuplot)\n"
    "\n"
    "options:\n"
    "  --out DIR          output folder (default bench/results)\n"
    "  --cache DIR        references and scratch (default OUT/cache)\n"
    "  --bin DIR          where photosplat-ref, -snap and -compare are (default:\n"
    "                     beside this program)\n"
    "  --scenes LIST      comma list of FILE.scn[:EXPOSURE] (default the four bench\n"
    "                     scenes in data/scenes)\n"
    "  --size WxH         image size of every run (default 256x256)\n"
    "  --budgets LIST     checkpoint seconds (default 0.05,0.1,0.2,0.5,1,2,5,10)\n"
    "  --quick            the six main configurations only, budgets up to 2 s\n"
    "  --threads N        tracing and rendering threads (default: all cores)\n"
    "  --replot           run nothing: remake bench.md and the plots from OUT/bench.csv\n"
    "                     (the scenes and budgets must be the run's)\n"
    "  --help             this text\n"
    "\n"
    "Exit status 0 on success, 2 on bad options or a failed run (one line on stderr).\n";

enum {
    BENCH_MAX_SCENES = 16,
    BENCH_MAX_BUDGETS = 32,
    /* whole (the picture less its specular layer, against the reference's
     * direct, caustic and indirect terms), direct, caustic, global, full (the
     * whole picture against the whole reference, specular paths included:
     * what mirrors and glass show) and the specular layer alone against the
     * reference's specular term. */
    BENCH_LAYERS = 6,
    BENCH_PLOTTED_LAYERS = 4,
    /* A child's exit status when it could not be started (the shell's). */
    BENCH_EXEC_FAILED = 127,
    BENCH_COMPONENTS = 4,
    /* A scene and the meshes it names are hashed whole up to this size. */
    BENCH_MAX_HASHED = 1 << 30,
};

/* The display's white in radiance units is 1 / exposure; these exposures put
 * each bench scene's lit walls near the top of the 8-bit range (as `make run`). */
typedef struct bench_scene {
    const char *path;
    double exposure;
} bench_scene;

static const bench_scene default_scenes[] = {
    {"data/scenes/cornell-caustic.scn", 0.3},
    {"data/scenes/cornell-caustic-area.scn", 0.3},
    {"data/scenes/ring-caustic.scn", 0.5},
    {"data/scenes/design-room.scn", 0.5},
};
#define BENCH_DEFAULT_EXPOSURE 0.5

static const double default_budgets[] = {0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10};
#define BENCH_QUICK_LAST_BUDGET 2.0

/* What a snapshot run varies. The first BENCH_MAIN_CONFIGS are the main
 * curves (the accurate splats, 8-bit with diffusion as the thesis, the float
 * buffer, each with both radius schedules, and the float buffer with the
 * global layer as illumination maps); the rest compare modes. */
typedef struct bench_config {
    ps_splat_mode splat;
    ps_color_depth depth;
    ps_precision precision;
    ps_radius_schedule schedule;
    ps_global_layer global;
} bench_config;

static const bench_config configs[] = {
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_8, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_8, PS_PRECISION_DIFFUSION, PS_RADIUS_PROGRESSIVE, PS_GLOBAL_SPLATS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_FLOAT, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_FLOAT, PS_PRECISION_DIFFUSION, PS_RADIUS_PROGRESSIVE, PS_GLOBAL_SPLATS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_FLOAT, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_MAPS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_FLOAT, PS_PRECISION_DIFFUSION, PS_RADIUS_PROGRESSIVE, PS_GLOBAL_MAPS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_8, PS_PRECISION_NONE, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_TRIANGLES, PS_COLOR_DEPTH_8, PS_PRECISION_COUNTER, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_POINTS, PS_COLOR_DEPTH_8, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_POINTS, PS_COLOR_DEPTH_FLOAT, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_SPRITES, PS_COLOR_DEPTH_8, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
    {PS_SPLAT_SPRITES, PS_COLOR_DEPTH_FLOAT, PS_PRECISION_DIFFUSION, PS_RADIUS_FIXED, PS_GLOBAL_SPLATS},
};
/* The buffer as the CSV and labels say it. */
static const char *depth_label(ps_color_depth d) { return d == PS_COLOR_DEPTH_FLOAT ? "float" : "8-bit"; }
#define BENCH_CONFIGS (sizeof configs / sizeof configs[0])
#define BENCH_MAIN_CONFIGS 6
/* The splat column: the mode, and "+maps" where the global layer is maps. */
static const char *splat_label(const bench_config *k)
{
    static const char *const maps[PS_SPLAT_MODE_COUNT] = {"points+maps", "triangles+maps", "sprites+maps"};
    return k->global == PS_GLOBAL_MAPS ? maps[k->splat] : ps_splat_mode_name(k->splat);
}

/* Progressive caps: far more photons than a run can trace in the longest
 * budget, so that time, not the cap, ends refinement. Multiples of the
 * scene's own counts. */
#define BENCH_CAP_FACTOR 40

/* The reference: converged well below the preview's error. Photon counts are
 * multiples of the scene's; the rest are photosplat-ref options. The box
 * filter, as the preview's pixels (GL samples each at its centre): with
 * photosplat-ref's default Mitchell filter, whose negative lobes ring
 * beside an area light seen directly (its direct term down to -2.3 W sr^-1
 * m^-2 on the ceiling beside the emitter, 1 310 pixels below zero at 256^2),
 * the pixels below zero made 0.034 of the area box's whole-image relMSE of
 * 0.061 at 3 s. */
#define BENCH_REF_PHOTON_FACTOR 20
static const char *const ref_settings[] = {"--spp", "16", "--k", "200", "--gather", "32", "--cache", "4",
                                           "--cache-rays", "1024", "--filter", "box", NULL};

/* Reference components and which snapshot layer each is compared with. */
static const char *const components[BENCH_COMPONENTS] = {"direct", "caustic", "indirect", "specular"};
static const char *const layer_names[BENCH_LAYERS] = {"whole", "direct", "caustic", "global", "full", "specular"};

typedef struct bench_options {
    const char *out, *cache, *bin;
    bench_scene scenes[BENCH_MAX_SCENES];
    int scene_count;
    double budgets[BENCH_MAX_BUDGETS];
    int budget_count;
    int width, height;
    bool quick, help, replot;
    int64_t threads;
    char *scene_text; /* --scenes, split in place: the paths point into it */
} bench_options;

/* One checkpoint of one run: its figures and each layer's error. */
typedef struct bench_row {
    int scene, config, checkpoint;
    double requested, seconds, radius[2];
    uint64_t emitted[2];
    double rmse[BENCH_LAYERS], relmse[BENCH_LAYERS];
} bench_row;

typedef struct bench_state {
    const bench_options *o;
    char self_dir[PATH_MAX];
    bench_row *rows;
    size_t row_count, row_cap;
    double ref_seconds[BENCH_MAX_SCENES];
    bool ref_cached[BENCH_MAX_SCENES];
    double started;
    char machine[512]; /* what the run measured of its machine (app/machine.h; "": --replot) */
} bench_state;

/* ---- options ----------------------------------------------------------------- */

/* "a.scn:0.3,b.scn": the text is the program's argument and outlives us, but
 * is split in place, so it is copied first. */
static ps_status parse_scenes(const char *text, bench_options *o, ps_error *err)
{
    char *copy = strdup(text);
    if (!copy)
        return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", PROG);
    free(o->scene_text);
    o->scene_text = copy;
    o->scene_count = 0;
    ps_status st = PS_OK;
    for (char *save = NULL, *item = strtok_r(copy, ",", &save); item && st == PS_OK;
         item = strtok_r(NULL, ",", &save)) {
        if (o->scene_count == BENCH_MAX_SCENES) {
            st = ps_error_set(err, PS_ERR_PARSE, "%s: --scenes: more than %d scenes", PROG, BENCH_MAX_SCENES);
            break;
        }
        bench_scene *s = &o->scenes[o->scene_count++];
        s->exposure = BENCH_DEFAULT_EXPOSURE;
        char *colon = strrchr(item, ':');
        if (colon) {
            char *end;
            *colon = '\0';
            s->exposure = strtod(colon + 1, &end);
            if (end == colon + 1 || *end || !(s->exposure > 0.0 && s->exposure <= 1e6))
                st = ps_error_set(err, PS_ERR_PARSE, "%s: --scenes: '%s' is not an exposure in (0, 1e6]", PROG,
                                  colon + 1);
        }
        s->path = item;
    }
    if (st == PS_OK && o->scene_count == 0)
        st = ps_error_set(err, PS_ERR_PARSE, "%s: --scenes: no scene in '%s'", PROG, text);
    return st;
}

static ps_status parse_args(int argc, char **argv, bench_options *o, ps_error *err)
{
    ps_cli cli = ps_cli_begin(PROG, argc, argv);
    memset(o, 0, sizeof *o);
    o->out = "bench/results";
    o->width = o->height = 256;
    o->scene_count = (int)(sizeof default_scenes / sizeof default_scenes[0]);
    memcpy(o->scenes, default_scenes, sizeof default_scenes);
    o->budget_count = (int)(sizeof default_budgets / sizeof default_budgets[0]);
    memcpy(o->budgets, default_budgets, sizeof default_budgets);
    bool budgets_given = false;
    ps_status st = PS_OK;
    const char *text;
    while (st == PS_OK && ps_cli_next(&cli)) {
        if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "-h")) {
            o->help = true;
            return PS_OK;
        } else if (ps_cli_is(&cli, "--quick")) {
            o->quick = true;
        } else if (ps_cli_is(&cli, "--replot")) {
            o->replot = true;
        } else if (ps_cli_is(&cli, "--out")) {
            st = ps_cli_string(&cli, &o->out, err);
        } else if (ps_cli_is(&cli, "--cache")) {
            st = ps_cli_string(&cli, &o->cache, err);
        } else if (ps_cli_is(&cli, "--bin")) {
            st = ps_cli_string(&cli, &o->bin, err);
        } else if (ps_cli_is(&cli, "--size")) {
            st = ps_cli_size(&cli, 16384, &o->width, &o->height, err);
        } else if (ps_cli_is(&cli, "--threads")) {
            st = ps_cli_int(&cli, 0, 1024, &o->threads, err);
        } else if (ps_cli_is(&cli, "--scenes")) {
            st = ps_cli_string(&cli, &text, err);
            if (st == PS_OK)
                st = parse_scenes(text, o, err);
        } else if (ps_cli_is(&cli, "--budgets")) {
            st = ps_cli_ascending(&cli, 1e-3, 1e5, o->budgets, BENCH_MAX_BUDGETS, &o->budget_count, err);
            budgets_given = true;
        } else if (ps_cli_positional(&cli)) {
            return ps_error_set(err, PS_ERR_PARSE, "%s: unexpected argument '%s' (see --help)", PROG, ps_cli_arg(&cli));
        } else {
            return ps_cli_unknown(&cli, err);
        }
    }
    if (st == PS_OK && o->quick && !budgets_given)
        while (o->budget_count > 1 && o->budgets[o->budget_count - 1] > BENCH_QUICK_LAST_BUDGET)
            o->budget_count--;
    return st;
}

/* ---- processes and files ----------------------------------------------------- */

/* Runs argv (argv[0] a path), its standard output into out (NUL-terminated,
 * truncated to size) or discarded, its standard error passed through.
 * Returns its exit status, or -1 when it could not run or was killed. */
static int run_program(char *const argv[], char *out, size_t size)
{
    int fd[2];
    if (pipe(fd) != 0)
        return -1;
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return -1;
    }
    if (pid == 0) {
        dup2(fd[1], STDOUT_FILENO);
        close(fd[0]);
        close(fd[1]);
        execvp(argv[0], argv); /* a path, or a program on PATH (gnuplot) */
        _exit(BENCH_EXEC_FAILED);
    }
    close(fd[1]);
    size_t used = 0;
    char sink[4096];
    for (;;) {
        char *dst = out && used + 1 < size ? out + used : sink;
        size_t room = out && used + 1 < size ? size - 1 - used : sizeof sink;
        ssize_t n = read(fd[0], dst, room);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        if (dst != sink)
            used += (size_t)n;
    }
    close(fd[0]);
    if (out && size > 0)
        out[used] = '\0';
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static ps_status run_checked(char *const argv[], char *out, size_t size, ps_error *err)
{
    int rc = run_program(argv, out, size);
    if (rc != 0)
        return ps_error_set(err, PS_ERR_IO, "%s: %s failed (exit status %d)", PROG, argv[0], rc);
    return PS_OK;
}

static ps_status make_dirs(const char *path, ps_error *err)
{
    char buf[PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return ps_error_set(err, PS_ERR_IO, "%s: path too long", path);
    for (char *p = buf + 1;; p++) {
        bool last = *p == '\0';
        if (*p == '/' || last) {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return ps_error_set(err, PS_ERR_IO, "%s: cannot create: %s", buf, strerror(errno));
            if (last)
                return PS_OK;
            *p = '/';
        }
    }
}

/* FNV-1a, 64 bits: enough to tell versions of a scene or a program apart. */
#define FNV_OFFSET 14695981039346656037ull
#define FNV_PRIME 1099511628211ull

static uint64_t fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * FNV_PRIME;
    return h;
}

static ps_status hash_file(uint64_t *h, const char *path, ps_error *err)
{
    char *text;
    size_t len;
    ps_status st = ps_read_file(path, BENCH_MAX_HASHED, &text, &len, err);
    if (st != PS_OK)
        return st;
    *h = fnv(*h, text, len);
    free(text);
    return PS_OK;
}

static bool file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

/* What the reference renderer is made of. From the source tree when the
 * bench runs in one (the folders the renderer's code lives in, so that a
 * change to the preview alone keeps the references), else the binary. */
static const char *const renderer_sources[] = {"src/core", "src/scene", "src/accel", "src/photon", "src/render",
                                                "src/image"};
#define RENDERER_MAIN "src/app/ref_main.c"

static int by_name(const struct dirent **a, const struct dirent **b) { return strcmp((*a)->d_name, (*b)->d_name); }

static ps_status hash_renderer(uint64_t *h, const char *binary, ps_error *err)
{
    if (!file_exists(RENDERER_MAIN))
        return hash_file(h, binary, err);
    ps_status st = hash_file(h, RENDERER_MAIN, err);
    for (size_t d = 0; st == PS_OK && d < sizeof renderer_sources / sizeof renderer_sources[0]; d++) {
        struct dirent **list;
        int n = scandir(renderer_sources[d], &list, NULL, by_name);
        if (n < 0)
            return ps_error_set(err, PS_ERR_IO, "%s: cannot list: %s", renderer_sources[d], strerror(errno));
        for (int i = 0; i < n; i++) {
            char path[PATH_MAX];
            snprintf(path, sizeof path, "%s/%s", renderer_sources[d], list[i]->d_name);
            if (st == PS_OK && file_exists(path)) {
                *h = fnv(*h, path, strlen(path) + 1);
                st = hash_file(h, path, err);
            }
            free(list[i]);
        }
        free(list);
    }
    return st;
}

/* The scene's key: its text, each .obj it names and the .mtl files beside
 * them (a renamed or edited mesh makes a new reference), the renderer
 * (hash_renderer) and the settings. */
static ps_status scene_key(const char *scene, const char *ref, char *const args[], uint64_t *key,
                           ps_error *err)
{
    uint64_t h = FNV_OFFSET;
    char *text;
    size_t len;
    ps_status st = ps_read_file(scene, BENCH_MAX_HASHED, &text, &len, err);
    if (st != PS_OK)
        return st;
    h = fnv(h, text, len);
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", scene);
    char *slash = strrchr(dir, '/');
    if (slash)
        slash[1] = '\0';
    else
        dir[0] = '\0';
    for (char *p = text; st == PS_OK && (p = strstr(p, "mesh")) != NULL; p += 4) {
        char name[PATH_MAX], path[2 * PATH_MAX];
        if (sscanf(p + 4, " %1023s", name) != 1)
            continue;
        snprintf(path, sizeof path, "%s%s", dir, name);
        if (file_exists(path))
            st = hash_file(&h, path, err);
        char *dot = strrchr(path, '.');
        if (st == PS_OK && dot && strlen(dot) == 4) {
            memcpy(dot, ".mtl", 4);
            if (file_exists(path))
                st = hash_file(&h, path, err);
        }
    }
    free(text);
    if (st == PS_OK)
        st = hash_renderer(&h, ref, err);
    for (int i = 0; st == PS_OK && args[i]; i++)
        h = fnv(h, args[i], strlen(args[i]) + 1);
    *key = h;
    return st;
}

static const char *stem(const char *path, char *buf, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    snprintf(buf, size, "%s", base);
    char *dot = strrchr(buf, '.');
    if (dot && dot != buf)
        *dot = '\0';
    return buf;
}

/* ---- references -------------------------------------------------------------- */

/* Removes the cache's older references of this scene and component (NAME-
 * COMPONENT-KEY.pfm with another key): a new one replaces them. */
static void remove_stale(const char *cache, const char *name, const char *component)
{
    char prefix[512];
    snprintf(prefix, sizeof prefix, "%s-%s-", name, component);
    size_t plen = strlen(prefix);
    DIR *d = opendir(cache);
    if (!d)
        return;
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        size_t len = strlen(e->d_name);
        /* NAME-COMPONENT- then 16 hex digits and .pfm */
        if (len == plen + 16 + 4 && strncmp(e->d_name, prefix, plen) == 0 && strcmp(e->d_name + len - 4, ".pfm") == 0 &&
            strspn(e->d_name + plen, "0123456789abcdef") == 16) {
            char path[2 * PATH_MAX];
            snprintf(path, sizeof path, "%s/%s", cache, e->d_name);
            remove(path);
        }
    }
    closedir(d);
}

static ps_status scene_photons(const char *scene, int64_t counts[2], ps_error *err)
{
    ps_scene *s;
    ps_status st = ps_scene_load(scene, NULL, &s, err);
    if (st != PS_OK)
        return st;
    const ps_scene_defaults *d = ps_scene_get_defaults(s);
    counts[0] = d->caustic_photons;
    counts[1] = d->global_photons;
    ps_scene_destroy(s);
    return PS_OK;
}

/* The reference of component c (and, once all four exist, their sum: the
 * whole image) in the cache, rendered when missing. */
static ps_status reference(bench_state *b, int si, char paths[BENCH_LAYERS][PATH_MAX], ps_error *err)
{
    const bench_options *o = b->o;
    const char *scene = o->scenes[si].path;
    char ref[PATH_MAX + 32], name[256], size[64], cp[32], gp[32], threads[32];
    snprintf(ref, sizeof ref, "%s/photosplat-ref", b->self_dir);
    int64_t counts[2];
    ps_status st = scene_photons(scene, counts, err);
    if (st != PS_OK)
        return st;
    snprintf(size, sizeof size, "%dx%d", o->width, o->height);
    snprintf(cp, sizeof cp, "%lld", (long long)(counts[0] * BENCH_REF_PHOTON_FACTOR));
    snprintf(gp, sizeof gp, "%lld", (long long)(counts[1] * BENCH_REF_PHOTON_FACTOR));
    snprintf(threads, sizeof threads, "%lld", (long long)o->threads);
    stem(scene, name, sizeof name);
    ps_image sum;
    memset(&sum, 0, sizeof sum);
    double t0 = ps_now_seconds();
    bool all_cached = true;
    for (int c = 0; c < BENCH_COMPONENTS && st == PS_OK; c++) {
        char *args[64];
        int n = 0;
        char out[PATH_MAX];
        args[n++] = ref;
        args[n++] = (char *)scene;
        args[n++] = "--size";
        args[n++] = size;
        args[n++] = "--component";
        args[n++] = (char *)components[c];
        args[n++] = "--caustic-photons";
        args[n++] = cp;
        args[n++] = "--global-photons";
        args[n++] = gp;
        if (o->threads > 0) {
            args[n++] = "--threads";
            args[n++] = threads;
        }
        for (int i = 0; ref_settings[i]; i++)
            args[n++] = (char *)ref_settings[i];
        args[n] = NULL;
        uint64_t key;
        /* The key leaves out the output path and the thread count: neither
         * changes the image. */
        char *keyed[64];
        int m = 0;
        for (int i = 1; i < n; i++)
            if (strcmp(args[i], "--threads") != 0 && strcmp(args[i - 1], "--threads") != 0)
                keyed[m++] = args[i];
        keyed[m] = NULL;
        st = scene_key(scene, ref, keyed, &key, err);
        if (st != PS_OK)
            break;
        snprintf(out, sizeof out, "%s/%s-%s-%016llx.pfm", o->cache, name, components[c], (unsigned long long)key);
        if (!file_exists(out)) {
            all_cached = false;
            remove_stale(o->cache, name, components[c]);
            printf("  reference %s: %s ...\n", components[c], out);
            fflush(stdout);
            args[n++] = "--hdr";
            args[n++] = out;
            args[n] = NULL;
            st = run_checked(args, NULL, 0, err);
        }
        snprintf(paths[c < 3 ? c + 1 : 5], PATH_MAX, "%s", out);
        /* Before the specular term: what the preview claims to show. */
        if (c == 3 && st == PS_OK) {
            snprintf(paths[0], PATH_MAX, "%s/%s-whole.pfm", o->cache, name);
            st = ps_pfm_write(&sum, paths[0], err);
        }
        ps_image img;
        if (st == PS_OK)
            st = ps_pfm_read(out, &img, err);
        if (st != PS_OK)
            break;
        if (!sum.rgb) {
            sum = img;
        } else {
            for (size_t i = 0; i < 3 * (size_t)img.width * (size_t)img.height; i++)
                sum.rgb[i] += img.rgb[i];
            ps_image_destroy(&img);
        }
    }
    /* The full image is the sum of the split rendering equation's terms
     * (test_render checks that they add up to --component all). */
    snprintf(paths[4], PATH_MAX, "%s/%s-full.pfm", o->cache, name);
    if (st == PS_OK)
        st = ps_pfm_write(&sum, paths[4], err);
    ps_image_destroy(&sum);
    b->ref_seconds[si] = ps_now_seconds() - t0;
    b->ref_cached[si] = all_cached;
    return st;
}

/* ---- snapshots ---------------------------------------------------------------- */

static bool config_wanted(const bench_options *o, size_t c) { return !o->quick || c < BENCH_MAIN_CONFIGS; }

static void config_label(size_t c, char *buf, size_t size)
{
    const bench_config *k = &configs[c];
    if (k->depth == PS_COLOR_DEPTH_FLOAT)
        snprintf(buf, size, "%s float %s", splat_label(k), ps_radius_schedule_name(k->schedule));
    else
        snprintf(buf, size, "%s 8-bit %s %s", splat_label(k), ps_precision_name(k->precision),
                 ps_radius_schedule_name(k->schedule));
}

static ps_status add_row(bench_state *b, const bench_row *r, ps_error *err)
{
    if (b->row_count == b->row_cap) {
        size_t cap = b->row_cap ? 2 * b->row_cap : 256;
        bench_row *rows = realloc(b->rows, cap * sizeof *rows);
        if (!rows)
            return ps_error_set(err, PS_ERR_NOMEM, "%s: out of memory", PROG);
        b->rows = rows;
        b->row_cap = cap;
    }
    b->rows[b->row_count++] = *r;
    return PS_OK;
}

/* "key=value" from photosplat-compare's line. */
static double field(const char *line, const char *key)
{
    const char *p = strstr(line, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

static ps_status compare(bench_state *b, const char *image, const char *reference_path, double clamp, double *rmse,
                         double *relmse, ps_error *err)
{
    char prog[PATH_MAX + 32], clamp_text[64], out[512];
    snprintf(prog, sizeof prog, "%s/photosplat-compare", b->self_dir);
    snprintf(clamp_text, sizeof clamp_text, "%.9g", clamp);
    char *args[] = {prog, (char *)image, (char *)reference_path, "--clamp", clamp_text, NULL};
    ps_status st = run_checked(args, out, sizeof out, err);
    if (st != PS_OK)
        return st;
    *rmse = field(out, "rmse=");
    *relmse = field(out, "relmse=");
    if (!isfinite(*rmse) || !isfinite(*relmse))
        return ps_error_set(err, PS_ERR_IO, "%s: cannot read photosplat-compare's output '%s'", PROG, out);
    return PS_OK;
}

/* Reads the checkpoint CSV snap wrote: one line a checkpoint. */
static ps_status read_checkpoints(const char *path, bench_row *rows, int count, ps_error *err)
{
    char *text;
    size_t len;
    ps_status st = ps_read_file(path, 1 << 20, &text, &len, err);
    if (st != PS_OK)
        return st;
    char *line = strchr(text, '\n'); /* past the header */
    for (int i = 0; i < count && st == PS_OK; i++) {
        int index;
        unsigned long long ce, ge;
        double lost;
        if (!line || sscanf(line + 1, "%d,%lf,%lf,%llu,%llu,%lf,%lf,%lf", &index, &rows[i].requested, &rows[i].seconds,
                            &ce, &ge, &rows[i].radius[0], &rows[i].radius[1], &lost) != 8 ||
            index != i)
            st = ps_error_set(err, PS_ERR_PARSE, "%s: checkpoint %d: unexpected line", path, i);
        rows[i].emitted[0] = ce;
        rows[i].emitted[1] = ge;
        if (line)
            line = strchr(line + 1, '\n');
    }
    free(text);
    return st;
}

/* PREFIX-I-nonspecular.pfm: checkpoint I's picture less its specular layer,
 * what the preview drew before it had one. */
static ps_status less_specular(const char *prefix, int i, ps_error *err)
{
    char path[2 * PATH_MAX];
    ps_image whole, spec;
    memset(&spec, 0, sizeof spec);
    snprintf(path, sizeof path, "%s-%d.pfm", prefix, i);
    ps_status st = ps_pfm_read(path, &whole, err);
    if (st != PS_OK)
        return st;
    snprintf(path, sizeof path, "%s-%d-specular.pfm", prefix, i);
    st = ps_pfm_read(path, &spec, err);
    if (st == PS_OK && (spec.width != whole.width || spec.height != whole.height))
        st = ps_error_set(err, PS_ERR_PARSE, "%s: %dx%d, the picture is %dx%d", path, spec.width, spec.height,
                          whole.width, whole.height);
    if (st == PS_OK) {
        for (size_t k = 0; k < 3 * (size_t)whole.width * (size_t)whole.height; k++)
            whole.rgb[k] -= spec.rgb[k];
        snprintf(path, sizeof path, "%s-%d-nonspecular.pfm", prefix, i);
        st = ps_pfm_write(&whole, path, err);
    }
    if (spec.rgb)
        ps_image_destroy(&spec);
    ps_image_destroy(&whole);
    return st;
}

static ps_status snapshots(bench_state *b, int si, char refs[BENCH_LAYERS][PATH_MAX], size_t c, ps_error *err)
{
    const bench_options *o = b->o;
    const bench_config *k = &configs[c];
    const bench_scene *sc = &o->scenes[si];
    char snap[PATH_MAX + 32], work[PATH_MAX + 16], prefix[PATH_MAX + 32], size[64], time_text[64], list[1024], exposure[64];
    char cp[32], gp[32], threads[32], csv[PATH_MAX + 64];
    snprintf(snap, sizeof snap, "%s/photosplat-snap", b->self_dir);
    snprintf(work, sizeof work, "%s/work", o->cache);
    ps_status st = make_dirs(work, err);
    if (st != PS_OK)
        return st;
    snprintf(prefix, sizeof prefix, "%s/cp", work);
    snprintf(csv, sizeof csv, "%s.csv", prefix);
    snprintf(size, sizeof size, "%dx%d", o->width, o->height);
    snprintf(time_text, sizeof time_text, "%.9g", o->budgets[o->budget_count - 1]);
    snprintf(exposure, sizeof exposure, "%.9g", sc->exposure);
    snprintf(threads, sizeof threads, "%lld", (long long)o->threads);
    size_t used = 0;
    for (int i = 0; i < o->budget_count; i++)
        used += (size_t)snprintf(list + used, sizeof list - used, "%s%.9g", i ? "," : "", o->budgets[i]);
    int64_t counts[2];
    st = scene_photons(sc->path, counts, err);
    if (st != PS_OK)
        return st;
    snprintf(cp, sizeof cp, "%lld", (long long)(counts[0] * BENCH_CAP_FACTOR));
    snprintf(gp, sizeof gp, "%lld", (long long)(counts[1] * BENCH_CAP_FACTOR));
    char *args[] = {snap, (char *)sc->path, "--size", size, "--exposure", exposure, "--time", time_text,
                    "--checkpoints", list, "--checkpoint-prefix", prefix, "--caustic-photons", cp,
                    "--global-photons", gp, "--splat", (char *)ps_splat_mode_name(k->splat),
                    "--color-depth", (char *)ps_color_depth_name(k->depth), "--precision",
                    (char *)ps_precision_name(k->precision), "--radius-schedule",
                    (char *)ps_radius_schedule_name(k->schedule), "--global-layer",
                    (char *)ps_global_layer_name(k->global),
                    /* all cores unless told: snap's own default */
                    o->threads > 0 ? "--threads" : NULL, threads, NULL};
    st = run_checked(args, NULL, 0, err);
    bench_row rows[BENCH_MAX_BUDGETS];
    memset(rows, 0, sizeof rows);
    if (st == PS_OK)
        st = read_checkpoints(csv, rows, o->budget_count, err);
    /* whole: the picture less its specular layer (-nonspecular, made here). */
    static const char *const suffix[BENCH_LAYERS] = {"-nonspecular", "-direct", "-caustic", "-global", "", "-specular"};
    for (int i = 0; i < o->budget_count && st == PS_OK; i++) {
        rows[i].scene = si;
        rows[i].config = (int)c;
        rows[i].checkpoint = i;
        st = less_specular(prefix, i, err);
        for (int l = 0; l < BENCH_LAYERS && st == PS_OK; l++) {
            char image[2 * PATH_MAX];
            snprintf(image, sizeof image, "%s-%d%s.pfm", prefix, i, suffix[l]);
            st = compare(b, image, refs[l], 1.0 / sc->exposure, &rows[i].rmse[l], &rows[i].relmse[l], err);
        }
        for (int l = 0; l < BENCH_LAYERS; l++) {
            char image[2 * PATH_MAX];
            snprintf(image, sizeof image, "%s-%d%s.pfm", prefix, i, suffix[l]);
            remove(image);
        }
        if (st == PS_OK)
            st = add_row(b, &rows[i], err);
    }
    remove(csv);
    return st;
}

/* ---- results ------------------------------------------------------------------ */

static ps_status write_csv(const bench_state *b, const char *path, ps_error *err)
{
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err->status;
    FILE *fp = ps_outfile_stream(out);
    fprintf(fp, "scene,splat,buffer,precision,schedule,checkpoint,requested_seconds,seconds,caustic_emitted,"
                "global_emitted,caustic_radius,global_radius");
    for (int l = 0; l < BENCH_LAYERS; l++)
        fprintf(fp, ",%s_rmse,%s_relmse", layer_names[l], layer_names[l]);
    fputc('\n', fp);
    for (size_t i = 0; i < b->row_count; i++) {
        const bench_row *r = &b->rows[i];
        const bench_config *k = &configs[r->config];
        char name[256];
        fprintf(fp, "%s,%s,%s,%s,%s,%d,%.6g,%.4f,%llu,%llu,%.6g,%.6g", stem(b->o->scenes[r->scene].path, name, sizeof name),
                splat_label(k), depth_label(k->depth), ps_precision_name(k->precision),
                ps_radius_schedule_name(k->schedule), r->checkpoint,
                r->requested, r->seconds, (unsigned long long)r->emitted[0], (unsigned long long)r->emitted[1],
                r->radius[0], r->radius[1]);
        for (int l = 0; l < BENCH_LAYERS; l++)
            fprintf(fp, ",%.6g,%.6g", r->rmse[l], r->relmse[l]);
        fputc('\n', fp);
    }
    return ps_outfile_commit(out, err);
}

static const bench_row *find_row(const bench_state *b, int si, size_t c, int cp)
{
    for (size_t i = 0; i < b->row_count; i++)
        if (b->rows[i].scene == si && b->rows[i].config == (int)c && b->rows[i].checkpoint == cp)
            return &b->rows[i];
    return NULL;
}

/* The first checkpoint from which the whole-image error stays within
 * BENCH_SETTLED of the run's last: where the curve has levelled out. */
#define BENCH_SETTLED 1.25
/* Where the table's full / whole column starts (seconds asked for). */
#define BENCH_FULL_FROM 2.0
/* A checkpoint is on time when its frame is done within 20 % of the seconds
 * asked for (the speed issue's goal for every checkpoint). The tables count
 * them twice: all, and from BENCH_ON_TIME_FROM on, since no first frame on
 * llvmpipe comes as early as the 0.05-0.2 s checkpoints. */
#define BENCH_ON_TIME 1.2
#define BENCH_ON_TIME_FROM 0.5

typedef struct bench_on_time {
    int on_time, count;       /* every checkpoint */
    int on_time_from, count_from; /* those asked for from BENCH_ON_TIME_FROM on */
} bench_on_time;

static void count_on_time(bench_on_time *t, const bench_row *r)
{
    bool ok = r->seconds <= BENCH_ON_TIME * r->requested;
    t->count++;
    t->on_time += ok;
    if (r->requested >= BENCH_ON_TIME_FROM) {
        t->count_from++;
        t->on_time_from += ok;
    }
}

static const bench_row *settled(const bench_state *b, int si, size_t c)
{
    const bench_row *last = find_row(b, si, c, b->o->budget_count - 1);
    if (!last)
        return NULL;
    const bench_row *from = last;
    for (int i = b->o->budget_count - 1; i >= 0; i--) {
        const bench_row *r = find_row(b, si, c, i);
        if (!r || r->relmse[0] > BENCH_SETTLED * last->relmse[0])
            break;
        from = r;
    }
    return from;
}

static ps_status write_markdown(const bench_state *b, const char *path, double total, ps_error *err)
{
    const bench_options *o = b->o;
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err->status;
    FILE *fp = ps_outfile_stream(out);
    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now));
    bench_on_time all_time = {0};
    fprintf(fp, "# Run time against error (photosplat-bench)\n\n");
    if (o->replot)
        fprintf(fp, "Remade by `%s --replot` on %s from bench.csv (%dx%d images); the run's own date, length and "
                    "reference times are not in the CSV. ",
                PROG, date, o->width, o->height);
    else
        fprintf(fp, "Made by `%s` on %s, %dx%d images, in %.0f s, on %s (app/machine.h: checkpoints' seconds "
                    "depend on these). ",
                PROG, date, o->width, o->height, total, b->machine);
    fprintf(fp, "Error: relMSE against the converged "
                "reference (photosplat-ref, per component), both images clamped to the display's white "
                "(1/exposure). Seconds: photosplat-snap's clock from its session's start to the checkpoint's "
                "frame: the first photons, tracing and drawing (the scene's loading, its meshes and the GL "
                "context come before, 0.02-0.06 s, not counted). `whole` is the picture less its specular layer against "
                "the reference's direct, caustic and indirect terms; `caustic`, `global`, `direct` and `specular` "
                "each layer alone against the caustic, indirect, direct and specular terms; `full` the whole "
                "picture against the whole reference, what mirrors and glass reflect and refract included "
                "(the specular layer's cube maps, docs/preview.md).\n\n");
    for (int si = 0; si < o->scene_count; si++) {
        char name[256];
        fprintf(fp, "## %s (exposure %g)\n\n", stem(o->scenes[si].path, name, sizeof name), o->scenes[si].exposure);
        if (!o->replot)
            fprintf(fp, "Reference: %s, %.0f s.\n\n", b->ref_cached[si] ? "from the cache" : "rendered",
                    b->ref_seconds[si]);
        fprintf(fp, "Whole-image relMSE at each checkpoint, headed by the seconds asked for; each cell says when "
                    "the frame it shows was done (a frame of millions of splats takes seconds):\n\n| configuration |");
        for (int i = 0; i < o->budget_count; i++)
            fprintf(fp, " %g s |", o->budgets[i]);
        double last = o->budgets[o->budget_count - 1];
        fprintf(fp, " caustic at %g s | global at %g s | direct at %g s | specular at %g s | full at %g s | "
                    "photons at %g s | settled from | full / whole from %g s, worst | on time |\n|---|",
                last, last, last, last, last, last, BENCH_FULL_FROM);
        for (int i = 0; i < o->budget_count + 9; i++)
            fprintf(fp, "---:|");
        fputc('\n', fp);
        for (size_t c = 0; c < BENCH_CONFIGS; c++) {
            if (!config_wanted(o, c))
                continue;
            char label[128];
            config_label(c, label, sizeof label);
            fprintf(fp, "| %s |", label);
            const bench_row *r = NULL;
            bench_on_time row_time = {0};
            for (int i = 0; i < o->budget_count; i++) {
                r = find_row(b, si, c, i);
                if (r) {
                    fprintf(fp, " %.4f @ %.1f s |", r->relmse[0], r->seconds);
                    count_on_time(&row_time, r);
                    count_on_time(&all_time, r);
                } else {
                    fprintf(fp, " |");
                }
            }
            const bench_row *s = settled(b, si, c);
            /* The goal: full within 1.5x of whole from 2 s on. */
            double worst = 0.0;
            for (int i = 0; i < o->budget_count; i++) {
                const bench_row *q = find_row(b, si, c, i);
                if (q && q->requested >= BENCH_FULL_FROM && q->relmse[0] > 0.0)
                    worst = fmax(worst, q->relmse[4] / q->relmse[0]);
            }
            if (r && s)
                fprintf(fp, " %.4f | %.4f | %.4f | %.4f | %.4f | %.3g | %.1f s | %.2fx | %d / %d |\n", r->relmse[2],
                        r->relmse[3], r->relmse[1], r->relmse[5], r->relmse[4], (double)(r->emitted[0] + r->emitted[1]),
                        s->seconds, worst, row_time.on_time, row_time.count);
            else
                fprintf(fp, " | | | | | | | | |\n");
        }
        fputc('\n', fp);
    }
    fprintf(fp, "\"Settled from\": the first checkpoint (actual seconds) whose whole-image error is within %.2fx "
                "of the run's last, where more time stops paying. \"On time\": the checkpoints whose frame was done "
                "within %.0f %% of the seconds asked for.\n\n",
            BENCH_SETTLED, 100.0 * (BENCH_ON_TIME - 1.0));
    fprintf(fp, "Checkpoints on time (within %.0f %%): %d of %d; of those asked for from %g s on, %d of %d.\n",
            100.0 * (BENCH_ON_TIME - 1.0), all_time.on_time, all_time.count, BENCH_ON_TIME_FROM,
            all_time.on_time_from, all_time.count_from);
    return ps_outfile_commit(out, err);
}

/* Gnuplot data: per scene, one block per configuration (blocks split by two
 * blank lines, gnuplot's `index`), columns seconds then each layer's relMSE. */
static ps_status write_data(const bench_state *b, int si, const char *path, ps_error *err)
{
    ps_outfile *out = ps_outfile_open(path, err);
    if (!out)
        return err->status;
    FILE *fp = ps_outfile_stream(out);
    for (size_t c = 0; c < BENCH_CONFIGS; c++) {
        if (!config_wanted(b->o, c))
            continue;
        char label[128];
        config_label(c, label, sizeof label);
        fprintf(fp, "# %s\n# seconds whole direct caustic global full specular photons\n", label);
        for (int i = 0; i < b->o->budget_count; i++) {
            const bench_row *r = find_row(b, si, c, i);
            if (r)
                fprintf(fp, "%.4f %.6g %.6g %.6g %.6g %.6g %.6g %llu\n", r->seconds, r->relmse[0], r->relmse[1],
                        r->relmse[2], r->relmse[3], r->relmse[4], r->relmse[5],
                        (unsigned long long)(r->emitted[0] + r->emitted[1]));
        }
        fprintf(fp, "\n\n");
    }
    return ps_outfile_commit(out, err);
}

/* The plot script: styles per configuration, then the main plot (whole image,
 * one panel a scene) and one plot a scene (one panel a layer). */
static ps_status write_plots(const bench_state *b, const char *script, ps_error *err)
{
    const bench_options *o = b->o;
    ps_outfile *out = ps_outfile_open(script, err);
    if (!out)
        return err->status;
    FILE *fp = ps_outfile_stream(out);
    fprintf(fp, "# Made by %s: gnuplot %s\nset datafile separator whitespace\n"
                "set logscale xy\nset grid\nset key top right font ',7' samplen 2 spacing 0.9\n"
                "set xlabel 'seconds'\nset ylabel 'relMSE'\n",
            PROG, script);
    /* Main curves solid and strong; comparisons thin and dashed. */
    int n = 0;
    for (size_t c = 0; c < BENCH_CONFIGS; c++) {
        if (!config_wanted(o, c))
            continue;
        char label[128];
        config_label(c, label, sizeof label);
        fprintf(fp, "set style line %d lw %s dt %d pt %d\ntitle%d = '%s'\n", n + 1,
                c < BENCH_MAIN_CONFIGS ? "2" : "1", c < BENCH_MAIN_CONFIGS ? 1 : 2, (int)(c % 7) + 1, n, label);
        n++;
    }
    int rows = (o->scene_count + 1) / 2, cols = o->scene_count > 1 ? 2 : 1;
    /* plot -2: whole-image error against photons, -1: against seconds (the
     * main plot), then one a scene, each layer against seconds. */
    for (int plot = -2; plot < o->scene_count; plot++) {
        char name[256];
        bool photons = plot == -2;
        if (plot < 0)
            fprintf(fp, "set terminal pngcairo size %d,%d\nset output '%s/%s.png'\nset multiplot layout %d,%d\n",
                    640 * cols, 480 * rows, o->out, photons ? "bench-photons" : "bench", rows, cols);
        else
            fprintf(fp, "set terminal pngcairo size 1280,960\nset output '%s/%s.png'\nset multiplot layout 2,2\n",
                    o->out, stem(o->scenes[plot].path, name, sizeof name));
        fprintf(fp, "set xlabel '%s'\n", photons ? "photons emitted (both maps)" : "seconds");
        int panels = plot < 0 ? o->scene_count : BENCH_PLOTTED_LAYERS;
        for (int p = 0; p < panels; p++) {
            int si = plot < 0 ? p : plot, layer = plot < 0 ? 0 : p;
            stem(o->scenes[si].path, name, sizeof name);
            fprintf(fp, "set title '%s: %s'\nplot ", name, layer_names[layer]);
            for (int i = 0; i < n; i++)
                fprintf(fp, "%s'%s/data/%s.dat' index %d using %d:%d with linespoints ls %d title title%d",
                        i ? ", \\\n     " : "", o->out, name, i, photons ? BENCH_LAYERS + 2 : 1, layer + 2, i + 1, i);
            fputc('\n', fp);
        }
        fprintf(fp, "unset multiplot\n");
    }
    return ps_outfile_commit(out, err);
}

static ps_status write_results(bench_state *b, double total, ps_error *err)
{
    const bench_options *o = b->o;
    char path[PATH_MAX + 64], data[PATH_MAX + 16];
    snprintf(data, sizeof data, "%s/data", o->out);
    ps_status st = make_dirs(data, err);
    snprintf(path, sizeof path, "%s/bench.csv", o->out);
    if (st == PS_OK)
        st = write_csv(b, path, err);
    snprintf(path, sizeof path, "%s/bench.md", o->out);
    if (st == PS_OK)
        st = write_markdown(b, path, total, err);
    for (int si = 0; si < o->scene_count && st == PS_OK; si++) {
        char name[256];
        snprintf(path, sizeof path, "%s/%s.dat", data, stem(o->scenes[si].path, name, sizeof name));
        st = write_data(b, si, path, err);
    }
    snprintf(path, sizeof path, "%s/plots.gp", data);
    if (st == PS_OK)
        st = write_plots(b, path, err);
    if (st != PS_OK)
        return st;
    char *args[] = {"gnuplot", path, NULL};
    int rc = run_program(args, NULL, 0);
    if (rc == BENCH_EXEC_FAILED) {
        printf("gnuplot is not installed (Debian: gnuplot-nox): plots not drawn; %s is ready for it\n", path);
        return PS_OK;
    }
    return rc == 0 ? PS_OK : ps_error_set(err, PS_ERR_IO, "%s: gnuplot %s failed (exit status %d)", PROG, path, rc);
}

/* bench.csv back into rows (write_csv's columns), for --replot. */
static ps_status read_csv(bench_state *b, const char *path, ps_error *err)
{
    const bench_options *o = b->o;
    char *text;
    size_t len;
    ps_status st = ps_read_file(path, 1u << 28, &text, &len, err);
    if (st != PS_OK)
        return st;
    int line = 1;
    for (char *save = NULL, *row = strtok_r(text, "\n", &save); row && st == PS_OK; row = strtok_r(NULL, "\n", &save)) {
        if (line++ == 1)
            continue; /* the header */
        char scene[256], splat[32], buffer[32], precision[32], schedule[32];
        bench_row r;
        memset(&r, 0, sizeof r);
        unsigned long long ce, ge;
        int used = 0;
        if (sscanf(row, "%255[^,],%31[^,],%31[^,],%31[^,],%31[^,],%d,%lf,%lf,%llu,%llu,%lf,%lf%n", scene, splat, buffer,
                   precision, schedule, &r.checkpoint, &r.requested, &r.seconds, &ce, &ge, &r.radius[0], &r.radius[1],
                   &used) != 12) {
            st = ps_error_set(err, PS_ERR_PARSE, "%s:%d: not a bench.csv row", path, line - 1);
            break;
        }
        r.emitted[0] = ce;
        r.emitted[1] = ge;
        const char *p = row + used;
        for (int l = 0; l < BENCH_LAYERS && st == PS_OK; l++) {
            int n = 0;
            if (sscanf(p, ",%lf,%lf%n", &r.rmse[l], &r.relmse[l], &n) != 2)
                st = ps_error_set(err, PS_ERR_PARSE, "%s:%d: missing errors", path, line - 1);
            p += n;
        }
        r.scene = r.config = -1;
        for (int si = 0; si < o->scene_count; si++) {
            char name[256];
            if (strcmp(stem(o->scenes[si].path, name, sizeof name), scene) == 0)
                r.scene = si;
        }
        for (size_t c = 0; c < BENCH_CONFIGS; c++) {
            const bench_config *k = &configs[c];
            if (!strcmp(splat_label(k), splat) && !strcmp(depth_label(k->depth), buffer) &&
                !strcmp(ps_precision_name(k->precision), precision) &&
                !strcmp(ps_radius_schedule_name(k->schedule), schedule))
                r.config = (int)c;
        }
        if (st == PS_OK && (r.scene < 0 || r.config < 0 || r.checkpoint < 0 || r.checkpoint >= o->budget_count))
            st = ps_error_set(err, PS_ERR_PARSE, "%s:%d: a scene, configuration or checkpoint this run does not have",
                              path, line - 1);
        if (st == PS_OK)
            st = add_row(b, &r, err);
    }
    free(text);
    return st;
}

/* ---- main --------------------------------------------------------------------- */

static ps_status run(bench_state *b, ps_error *err)
{
    const bench_options *o = b->o;
    /* Everything that can be refused is refused before the first line of
     * progress: the scenes load, the programs are there. */
    static const char *const programs[] = {"photosplat-ref", "photosplat-snap", "photosplat-compare"};
    for (size_t i = 0; i < sizeof programs / sizeof programs[0]; i++) {
        char path[PATH_MAX + 32];
        snprintf(path, sizeof path, "%s/%s", b->self_dir, programs[i]);
        if (access(path, X_OK) != 0)
            return ps_error_set(err, PS_ERR_IO, "%s: %s: not found or not executable (give --bin)", PROG, path);
    }
    ps_status st = PS_OK;
    for (int si = 0; si < o->scene_count && st == PS_OK; si++) {
        int64_t counts[2];
        st = scene_photons(o->scenes[si].path, counts, err);
    }
    if (st == PS_OK)
        st = make_dirs(o->cache, err);
    /* The machine, before anything else has run (app/machine.h): its first
     * scene's photon paths, and what memory never written costs. */
    if (st == PS_OK) {
        ps_machine m;
        char name[256];
        st = ps_machine_measure(o->scenes[0].path, &m, err);
        if (st == PS_OK) {
            ps_machine_describe(&m, stem(o->scenes[0].path, name, sizeof name), b->machine, sizeof b->machine);
            printf("machine: %s\n", b->machine);
            fflush(stdout);
        }
    }
    int total_configs = 0;
    for (size_t c = 0; c < BENCH_CONFIGS; c++)
        total_configs += config_wanted(o, c);
    for (int si = 0; si < o->scene_count && st == PS_OK; si++) {
        char refs[BENCH_LAYERS][PATH_MAX];
        printf("%s: references\n", o->scenes[si].path);
        fflush(stdout);
        st = reference(b, si, refs, err);
        int done = 0;
        for (size_t c = 0; c < BENCH_CONFIGS && st == PS_OK; c++) {
            if (!config_wanted(o, c))
                continue;
            char label[128];
            config_label(c, label, sizeof label);
            double t0 = ps_now_seconds();
            st = snapshots(b, si, refs, c, err);
            const bench_row *last = st == PS_OK ? find_row(b, si, c, o->budget_count - 1) : NULL;
            if (last)
                printf("  [%d/%d] %-36s %6.1f s: whole relMSE %.4f, caustic %.4f after %.2f s\n", ++done,
                       total_configs, label, ps_now_seconds() - t0, last->relmse[0], last->relmse[2], last->seconds);
            fflush(stdout);
        }
    }
    if (st == PS_OK)
        st = write_results(b, ps_now_seconds() - b->started, err);
    return st;
}

int main(int argc, char **argv)
{
    ps_error err;
    ps_error_clear(&err);
    bench_options o;
    ps_status st = parse_args(argc, argv, &o, &err);
    if (st != PS_OK || o.help) {
        free(o.scene_text);
        if (st != PS_OK)
            return ps_cli_fail(&err);
        fputs(usage, stdout);
        return PS_EXIT_OK;
    }
    bench_state b;
    memset(&b, 0, sizeof b);
    b.o = &o;
    b.started = ps_now_seconds();
    char cache[PATH_MAX];
    if (!o.cache) {
        snprintf(cache, sizeof cache, "%s/cache", o.out);
        o.cache = cache;
    }
    /* The other programs: --bin, else this program's own folder. */
    if (o.bin) {
        snprintf(b.self_dir, sizeof b.self_dir, "%s", o.bin);
    } else {
        ssize_t n = readlink("/proc/self/exe", b.self_dir, sizeof b.self_dir - 1);
        if (n <= 0) {
            free(o.scene_text);
            ps_error_set(&err, PS_ERR_IO, "%s: cannot find my own folder: give --bin", PROG);
            return ps_cli_fail(&err);
        }
        b.self_dir[n] = '\0';
        *strrchr(b.self_dir, '/') = '\0';
    }
    if (o.replot) {
        char path[PATH_MAX + 16];
        snprintf(path, sizeof path, "%s/bench.csv", o.out);
        st = read_csv(&b, path, &err);
        if (st == PS_OK)
            st = write_results(&b, 0.0, &err);
    } else {
        st = run(&b, &err);
    }
    free(b.rows);
    free(o.scene_text);
    if (st != PS_OK)
        return ps_cli_fail(&err);
    printf("wrote %s/bench.csv, bench.md, bench.png and one plot a scene in %.0f s\n", o.out,
           ps_now_seconds() - b.started);
    return PS_EXIT_OK;
}
