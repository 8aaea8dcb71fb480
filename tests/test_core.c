/* test_core.c: vectors, boxes, transforms, strict numbers, atomic output, the
 * memory budget and large blocks, the interrupt flag, the name map and a
 * thread's low priority. */
#define _GNU_SOURCE /* gettid: a thread's own nice value */
#include "test.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h> /* mallinfo2: large_blocks_mapped */
#endif

#include "app/interrupt.h"
#include "core/fileio.h"
#include "core/jobs.h"
#include "core/memory.h"
#include "core/namemap.h"
#include "core/number.h"
#include "core/rng.h"
#include "core/transform.h"
#include "core/vec.h"

static void vector_algebra(void **state)
{
    (void)state;
    ps_vec3 x = ps_v3(1, 0, 0), y = ps_v3(0, 1, 0);
    ps_vec3 z = ps_v3_cross(x, y);
    assert_near(z.z, 1, 0);
    assert_near(ps_v3_dot(ps_v3(1, 2, 3), ps_v3(4, -5, 6)), 12, 0);
    assert_near(ps_v3_len(ps_v3(3, 4, 12)), 13, 1e-15);
    ps_vec3 zero = ps_v3_norm(ps_v3(0, 0, 0));
    assert_true(zero.x == 0 && zero.y == 0 && zero.z == 0); /* no NaN from a zero vector */
    assert_near(ps_v3_len(ps_v3_norm(ps_v3(1e-300, 1e-300, 0))), 1, 1e-12);
    assert_near(ps_v3_norm(ps_v3(3e200, 4e200, 0)).y, 0.8, 1e-15);
    assert_near(ps_v3_get(ps_v3(7, 8, 9), 2), 9, 0);
}

/* The splat basis must be orthonormal for every normal, including each axis
 * in both directions and normals a hair away from them. */
static void basis_is_orthonormal(void **state)
{
    (void)state;
    ps_vec3 special[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                         {1e-9, 0, -1}, {0, 1e-12, -1}, {1e-12, 1e-12, 1}};
    ps_rng r = ps_rng_make(1, PS_STREAM_TEST, 0);
    for (int k = 0; k < 2000; k++) {
        ps_vec3 n = k < 9 ? special[k]
                          : ps_v3(ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5);
        if (k >= 9 && ps_v3_len(n) < 1e-3)
            continue;
        n = ps_v3_norm(n);
        ps_vec3 t, b;
        ps_v3_basis(n, &t, &b);
        assert_near(ps_v3_len(t), 1, 1e-12);
        assert_near(ps_v3_len(b), 1, 1e-12);
        assert_near(ps_v3_dot(t, n), 0, 1e-12);
        assert_near(ps_v3_dot(b, n), 0, 1e-12);
        assert_near(ps_v3_dot(t, b), 0, 1e-12);
        /* right-handed: t x b = n */
        assert_near(ps_v3_dot(ps_v3_cross(t, b), n), 1, 1e-12);
    }
}

/* The slab test against a brute-force walk along the ray. */
static void aabb_slab_test(void **state)
{
    (void)state;
    ps_aabb b = {{-1, -2, -3}, {1, 2, 3}};
    assert_near(ps_aabb_area(b), 2 * (2 * 4 + 4 * 6 + 6 * 2), 0);
    assert_true(ps_aabb_is_empty(ps_aabb_empty()));
    assert_near(ps_aabb_area(ps_aabb_empty()), 0, 0);
    assert_near(ps_aabb_extent(b), 3, 0);
    ps_rng r = ps_rng_make(2, PS_STREAM_TEST, 0);
    int hits = 0;
    for (int k = 0; k < 5000; k++) {
        ps_vec3 o = ps_v3(8 * ps_rng_uniform(&r) - 4, 8 * ps_rng_uniform(&r) - 4, 8 * ps_rng_uniform(&r) - 4);
        ps_vec3 d = ps_v3(ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5, ps_rng_uniform(&r) - 0.5);
        if (k % 7 == 0)
            d.y = 0; /* axis-parallel rays: 1/0 = inf in the slab test */
        ps_ray ray = ps_ray_make(o, d);
        ps_vec3 inv = ps_v3(1 / d.x, 1 / d.y, 1 / d.z);
        double t0, t1;
        bool hit = ps_aabb_hit(b, ray, inv, 0, 100, &t0, &t1);
        /* brute force: sample the segment finely */
        bool brute = false;
        for (int s = 0; s <= 20000 && !brute; s++)
            brute = ps_aabb_contains(b, ps_ray_at(ray, 100.0 * s / 20000));
        if (brute)
            assert_true(hit);
        if (hit) {
            hits++;
            assert_true(ps_aabb_contains((ps_aabb){{-1 - 1e-9, -2 - 1e-9, -3 - 1e-9}, {1 + 1e-9, 2 + 1e-9, 3 + 1e-9}},
                                         ps_ray_at(ray, 0.5 * (t0 + t1))));
        }
    }
    assert_true(hits > 500);
}

static void transforms(void **state)
{
    (void)state;
    /* compose(a, b) applies b first. */
    ps_xform s = ps_xform_scale(ps_v3(2, 2, 2)), t = ps_xform_translate(ps_v3(1, 0, 0));
    ps_xform ts = ps_xform_compose(t, s), st = ps_xform_compose(s, t);
    assert_near(ps_xform_point(&ts, ps_v3(1, 0, 0)).x, 3, 0);
    assert_near(ps_xform_point(&st, ps_v3(1, 0, 0)).x, 4, 0);
    /* Right-handed rotation: +90 deg about z takes x to y. */
    ps_xform rz = ps_xform_rotate(ps_v3(0, 0, 5), 90);
    ps_vec3 p = ps_xform_point(&rz, ps_v3(1, 0, 0));
    assert_near(p.x, 0, 1e-15);
    assert_near(p.y, 1, 1e-15);
    assert_near(ps_xform_det(rz), 1, 1e-15);
    assert_near(ps_xform_det(ps_xform_scale(ps_v3(-1, 2, 3))), -6, 0);
    /* Vectors ignore translation. */
    assert_near(ps_xform_vector(&ts, ps_v3(1, 0, 0)).x, 2, 0);
    /* Normals stay perpendicular to transformed tangents under a shear-like
     * composite, for random planes. */
    ps_xform m = ps_xform_compose(ps_xform_rotate(ps_v3(1, 2, 3), 37), ps_xform_scale(ps_v3(3, -0.5, 2)));
    ps_rng r = ps_rng_make(3, PS_STREAM_TEST, 0);
    for (int k = 0; k < 200; k++) {
        ps_vec3 n = ps_v3_norm(ps_v3(ps_rng_uniform(&r) - .5, ps_rng_uniform(&r) - .5, ps_rng_uniform(&r) - .5));
        ps_vec3 a, b;
        ps_v3_basis(n, &a, &b);
        ps_vec3 n2 = ps_xform_normal(&m, n);
        assert_near(ps_v3_len(n2), 1, 1e-12);
        assert_near(ps_v3_dot(n2, ps_xform_vector(&m, a)), 0, 1e-12);
        assert_near(ps_v3_dot(n2, ps_xform_vector(&m, b)), 0, 1e-12);
        /* Outward stays outward: the transformed normal points the same way as
         * the transformed offset of a point just above the surface. */
        assert_true(ps_v3_dot(n2, ps_xform_vector(&m, n)) > 0);
    }
}

static void strict_numbers(void **state)
{
    (void)state;
    double d;
    int64_t i;
    assert_true(ps_parse_double("1.5e-3", &d) && d == 1.5e-3);
    assert_true(ps_parse_double("-0", &d) && d == 0);
    assert_true(ps_parse_double("1e-320", &d)); /* a denormal is a finite number */
    const char *bad[] = {"", "nan", "NaN", "inf", "-Infinity", "1e999", "1.0x", "0x", " ", "1 2", "--1"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
        if (ps_parse_double(bad[k], &d))
            fail_msg("'%s' was accepted as %g", bad[k], d);
    assert_true(ps_parse_int64("-42", &i) && i == -42);
    assert_true(ps_parse_int64("9223372036854775807", &i) && i == INT64_MAX);
    assert_false(ps_parse_int64("9223372036854775808", &i));
    assert_false(ps_parse_int64("1.0", &i));
    assert_false(ps_parse_int64("12abc", &i));
    assert_false(ps_parse_int64("", &i));
}

static bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Output appears whole under its name on commit, and not at all on abort. */
static void atomic_output(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s", test_path("out.txt"));
    remove(path);
    ps_error err;
    ps_outfile *f = ps_outfile_open(path, &err);
    assert_non_null(f);
    fputs("hello", ps_outfile_stream(f));
    assert_false(exists(path)); /* nothing under the name while writing */
    assert_int_equal(ps_outfile_commit(f, &err), PS_OK);
    char *text;
    size_t len;
    assert_int_equal(ps_read_file(path, 100, &text, &len, &err), PS_OK);
    assert_string_equal(text, "hello");
    free(text);

    f = ps_outfile_open(path, &err);
    fputs("partial", ps_outfile_stream(f));
    ps_outfile_abort(f);
    assert_int_equal(ps_read_file(path, 100, &text, &len, &err), PS_OK);
    assert_string_equal(text, "hello"); /* the old file is untouched */
    free(text);

    /* A directory that does not exist: refused at open, nothing created. */
    assert_null(ps_outfile_open("build/no/such/dir/x.png", &err));
    assert_int_equal(err.status, PS_ERR_IO);
    assert_non_null(strstr(err.msg, "build/no/such/dir/x.png: cannot create"));
    /* A directory as the output name. */
    assert_null(ps_outfile_open("build", &err));
    assert_non_null(strstr(err.msg, "is a directory"));

    /* A device (as /dev/stdout would be) is written to, never replaced. */
    f = ps_outfile_open("/dev/null", &err);
    assert_non_null(f);
    fputs("discarded", ps_outfile_stream(f));
    assert_int_equal(ps_outfile_commit(f, &err), PS_OK);
    struct stat st;
    assert_int_equal(stat("/dev/null", &st), 0);
    assert_true(S_ISCHR(st.st_mode));

    /* Through a symbolic link the linked file is replaced and the link kept. */
    char link[1024];
    snprintf(link, sizeof link, "%s", test_path("link.txt"));
    remove(link);
    assert_int_equal(symlink("out.txt", link), 0);
    f = ps_outfile_open(link, &err);
    assert_non_null(f);
    fputs("via link", ps_outfile_stream(f));
    assert_int_equal(ps_outfile_commit(f, &err), PS_OK);
    assert_int_equal(lstat(link, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_int_equal(ps_read_file(path, 100, &text, &len, &err), PS_OK);
    assert_string_equal(text, "via link");
    free(text);
}

static void read_file_limits(void **state)
{
    (void)state;
    char *text;
    size_t len;
    ps_error err;
    const char *path = test_path("ten.txt");
    FILE *fp = fopen(path, "wb");
    fputs("0123456789", fp);
    fclose(fp);
    assert_int_equal(ps_read_file(path, 10, &text, &len, &err), PS_OK);
    assert_int_equal(len, 10);
    free(text);
    assert_int_equal(ps_read_file(path, 9, &text, &len, &err), PS_ERR_LIMIT);
    assert_null(text);
    assert_int_equal(ps_read_file("/dev/zero", 100, &text, &len, &err), PS_ERR_IO); /* a device never ends */
    assert_non_null(strstr(err.msg, "not a regular file"));
}

/* The name map keeps the first or the last index of a name as asked, and
 * survives growing well past its initial size. */
static void name_map(void **state)
{
    (void)state;
    ps_namemap *m = ps_namemap_create();
    assert_non_null(m);
    assert_int_equal(ps_namemap_find(m, "a"), -1);
    char name[32];
    for (int i = 0; i < 5000; i++) {
        snprintf(name, sizeof name, "n%d", i);
        assert_true(ps_namemap_put(m, name, i, false));
    }
    for (int i = 0; i < 5000; i += 7) {
        snprintf(name, sizeof name, "n%d", i);
        assert_int_equal(ps_namemap_find(m, name), i);
    }
    assert_true(ps_namemap_put(m, "n3", 99, false));
    assert_int_equal(ps_namemap_find(m, "n3"), 3);
    assert_true(ps_namemap_put(m, "n3", 99, true));
    assert_int_equal(ps_namemap_find(m, "n3"), 99);
    assert_int_equal(ps_namemap_find(m, "n5000"), -1);
    assert_int_equal(ps_namemap_find(m, ""), -1);
    assert_true(ps_namemap_put(m, "", 7, false));
    assert_int_equal(ps_namemap_find(m, ""), 7);
    ps_namemap_destroy(m);
    ps_namemap_destroy(NULL);
}

static void line_lengths(void **state)
{
    (void)state;
    assert_int_equal(ps_line_length(""), 0);
    assert_int_equal(ps_line_length("abc"), 3);
    assert_int_equal(ps_line_length("ab\ncd"), 2);
    assert_int_equal(ps_line_length("\n"), 0);
}

static void error_messages_are_one_line(void **state)
{
    (void)state;
    ps_error err;
    assert_int_equal(ps_error_set(&err, PS_ERR_PARSE, "%s:%d: bad\nthing", "a\nb.scn", 3), PS_ERR_PARSE);
    assert_null(strchr(err.msg, '\n'));
    assert_string_equal(err.msg, "a b.scn:3: bad thing");
    assert_int_equal(ps_error_set(NULL, PS_ERR_IO, "x"), PS_ERR_IO); /* NULL err is allowed */
    ps_error_clear(&err);
    assert_int_equal(err.status, PS_OK);
    assert_string_equal(ps_status_name(PS_ERR_NOMEM), "out of memory");
}

/* A located error keeps its line as a field, with the same one-line text
 * ps_error_set would make; an unlocated one, or a cleared one, has line 0. */
static void errors_carry_their_line(void **state)
{
    (void)state;
    ps_error err;
    assert_int_equal(ps_error_at(&err, PS_ERR_RANGE, "a\nb.obj", 17, "'%s' is %d", "v", 4), PS_ERR_RANGE);
    assert_string_equal(err.msg, "a b.obj:17: 'v' is 4");
    assert_int_equal(err.line, 17);
    assert_int_equal(err.status, PS_ERR_RANGE);
    assert_int_equal(ps_error_set(&err, PS_ERR_IO, "%s: cannot open", "x.obj"), PS_ERR_IO);
    assert_int_equal(err.line, 0);
    ps_error_at(&err, PS_ERR_PARSE, "x", 2, "y");
    ps_error_clear(&err);
    assert_int_equal(err.line, 0);
    assert_int_equal(ps_error_at(NULL, PS_ERR_PARSE, "x", 1, "y"), PS_ERR_PARSE); /* NULL err is allowed */
    /* A file name that fills the message leaves a truncated, still one-line message. */
    char longname[2 * PS_ERROR_MSG_MAX];
    memset(longname, 'n', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    ps_error_at(&err, PS_ERR_PARSE, longname, 5, "problem");
    assert_int_equal(strlen(err.msg), PS_ERROR_MSG_MAX - 1);
    assert_int_equal(err.line, 5);
}

/* PS_MEMORY_LIMIT sets the budget; sizes parse with K/M/G; a check over it
 * is PS_ERR_LIMIT with the one-line message; products saturate. */
static void memory_budget(void **state)
{
    (void)state;
    uint64_t v = 0;
    assert_true(ps_memory_parse_size("512M", &v));
    assert_true(v == 512ull << 20);
    assert_true(ps_memory_parse_size("3g", &v) && v == 3ull << 30);
    assert_true(ps_memory_parse_size("4096", &v) && v == 4096);
    assert_false(ps_memory_parse_size("0", &v));
    assert_false(ps_memory_parse_size("-1G", &v));
    assert_false(ps_memory_parse_size("12T", &v));
    assert_false(ps_memory_parse_size("", &v));
    assert_false(ps_memory_parse_size(NULL, &v));
    assert_true(ps_memory_mul(UINT64_MAX / 2, 3) == UINT64_MAX);
    assert_true(ps_memory_mul(0, UINT64_MAX) == 0);

    setenv(PS_MEMORY_LIMIT_ENV, "64M", 1);
    assert_true(ps_memory_budget() == 64ull << 20);
    ps_error err;
    assert_int_equal(ps_memory_check(64ull << 20, "prog", "it", &err), PS_OK);
    assert_int_equal(ps_memory_check((64ull << 20) + 1, "prog", "a thing", &err), PS_ERR_LIMIT);
    assert_string_equal(err.msg, "prog: a thing would need 64 MiB, more than the memory budget of 64 MiB (set by "
                                 "PS_MEMORY_LIMIT)");
    assert_int_equal(ps_memory_check(3ull << 30, NULL, "it", &err), PS_ERR_LIMIT);
    assert_string_equal(err.msg, "it would need 3.0 GiB, more than the memory budget of 64 MiB (set by PS_MEMORY_LIMIT)");
    /* Without the variable (or with junk in it): 3/4 of physical memory. */
    setenv(PS_MEMORY_LIMIT_ENV, "lots", 1);
    uint64_t physical = (uint64_t)sysconf(_SC_PHYS_PAGES) * (uint64_t)sysconf(_SC_PAGESIZE);
    assert_true(ps_memory_budget() == (uint64_t)((double)physical * PS_MEMORY_FRACTION));
    unsetenv(PS_MEMORY_LIMIT_ENV);
    assert_int_equal(ps_memory_check(UINT64_MAX, "prog", "everything", &err), PS_ERR_LIMIT);
    assert_non_null(strstr(err.msg, "(75 % of physical memory)"));
}

/* Output paths are checked before any work: nothing is left by the check;
 * a FIFO without a reader fails at once; a device that fills up fails at
 * commit and leaves nothing. */
static void output_checks(void **state)
{
    (void)state;
    ps_error err;
    char dir[1024], path[1100];
    snprintf(dir, sizeof dir, "%s", test_path("outcheck"));
    mkdir(dir, 0777);
    snprintf(path, sizeof path, "%s/a.png", dir);
    remove(path);
    assert_int_equal(ps_check_output_path(path, &err), PS_OK);
    DIR *d = opendir(dir);
    assert_non_null(d);
    int entries = 0;
    for (struct dirent *e; (e = readdir(d));)
        entries += e->d_name[0] != '.';
    closedir(d);
    assert_int_equal(entries, 0); /* the probe's temporary file is gone */
    assert_int_equal(ps_check_output_path(dir, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "is a directory"));
    snprintf(path, sizeof path, "%s/none/a.png", dir);
    assert_int_equal(ps_check_output_path(path, &err), PS_ERR_IO);
    assert_non_null(strstr(err.msg, "none/a.png: cannot create: No such file or directory"));
    assert_int_equal(ps_check_output_path("/dev/null", &err), PS_OK);

    snprintf(path, sizeof path, "%s/fifo", dir);
    remove(path);
    assert_int_equal(mkfifo(path, 0600), 0);
    assert_null(ps_outfile_open(path, &err)); /* no reader: ENXIO, not a hang */
    assert_non_null(strstr(err.msg, "fifo: cannot open: No such device or address"));
    remove(path);

    ps_outfile *f = ps_outfile_open("/dev/full", &err);
    assert_non_null(f);
    for (int i = 0; i < 10000; i++)
        fputs("more than a stdio buffer ", ps_outfile_stream(f));
    assert_int_equal(ps_outfile_commit(f, &err), PS_ERR_IO);
    assert_string_equal(err.msg, "/dev/full: write failed: No space left on device");
}

/* A worker thread sees a flag another thread raises (the flag is atomic:
 * workers read it while the signal handler's thread stores to it). */
typedef struct spinner {
    const ps_cancel_flag *flag;
    atomic_int started;
    long long spins;
    bool saw;
} spinner;

static void *spin_until_cancelled(void *arg)
{
    spinner *s = arg;
    atomic_store(&s->started, 1);
    /* Bounded, so that a flag never seen fails the test instead of hanging it. */
    for (s->spins = 0; s->spins < 4000000000LL && !s->saw; s->spins++)
        s->saw = ps_cancelled(s->flag) != 0;
    return NULL;
}

/* A thread's own nice value. */
static int own_nice(void)
{
    errno = 0;
    return getpriority(PRIO_PROCESS, (id_t)gettid());
}

static void *nice_of_started(void *arg)
{
    *(int *)arg = own_nice();
    return NULL;
}

static void *lowered(void *arg)
{
    int *seen = arg;
    seen[0] = own_nice();
    ps_thread_low_priority();
    seen[1] = own_nice();
    pthread_t t;
    if (pthread_create(&t, NULL, nice_of_started, &seen[2]) == 0)
        pthread_join(t, NULL);
    return NULL;
}

/* ps_thread_low_priority: the calling thread at nice 10 (or nicer), the threads it
 * starts after it too (the tracer's workers under a first round traced
 * beside the drawing), the thread that started it as it was. */
static void low_priority_thread(void **state)
{
    (void)state;
    int before = own_nice(), seen[3] = {-100, -100, -100};
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, lowered, seen), 0);
    pthread_join(t, NULL);
    printf("nice: %d before, %d after, %d in a thread it started; the caller %d\n", seen[0], seen[1], seen[2],
           own_nice());
    assert_int_equal(seen[0], before);
    assert_int_equal(seen[1], before > PS_THREAD_LOW_NICE ? before : PS_THREAD_LOW_NICE);
    assert_int_equal(seen[2], seen[1]);
    assert_int_equal(own_nice(), before);
}

static void cancel_flag_across_threads(void **state)
{
    (void)state;
    assert_false(ps_cancelled(NULL));
    ps_cancel_flag flag;
    atomic_init(&flag, 0);
    spinner s = {&flag, 0, 0, false};
    pthread_t tid;
    assert_int_equal(pthread_create(&tid, NULL, spin_until_cancelled, &s), 0);
    while (!atomic_load(&s.started))
        ;
    assert_false(ps_cancelled(&flag));
    atomic_store(&flag, SIGINT);
    pthread_join(tid, NULL);
    assert_true(s.saw);
    assert_true(ps_cancelled(&flag));
}

/* The programs' SIGINT/SIGTERM flag: the signal's number, the exit status
 * 128 + it, the handler gone after the first signal; SIGXFSZ ignored. */
static void interrupt_flag(void **state)
{
    (void)state;
    const ps_cancel_flag *flag = ps_interrupt_install();
    assert_false(ps_cancelled(flag));
    assert_int_equal(ps_interrupt_exit_status(), 130); /* none yet: as for SIGINT */
    raise(SIGTERM);
    assert_true(ps_cancelled(flag));
    assert_int_equal(atomic_load(flag), SIGTERM);
    assert_int_equal(ps_interrupt_exit_status(), 143);
    struct sigaction sa;
    assert_int_equal(sigaction(SIGTERM, NULL, &sa), 0);
    assert_true(sa.sa_handler == SIG_DFL); /* a second SIGTERM would end the program */
    assert_int_equal(sigaction(SIGXFSZ, NULL, &sa), 0);
    assert_true(sa.sa_handler == SIG_IGN);
    signal(SIGINT, SIG_DFL);
    signal(SIGXFSZ, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
}

/* ps_memory_set_drawing_policy: a large block is mapped on its own even
 * after a bigger one was freed (glibc would have raised its threshold to that
 * size and served the next from the heap, where freed blocks stay resident:
 * the soak's memory grew 10-15 MiB), and small blocks freed at the heap's top
 * stay with the process up to PS_MEMORY_TRIM_THRESHOLD (the trim threshold
 * fixed at 128 KiB gave them back to the kernel after every llvmpipe scene,
 * and the next faulted them in again). Counted by glibc's mapped blocks and
 * the top's releasable bytes; not under ASan, whose allocator is its own. */
static void drawing_policy(void **state)
{
    (void)state;
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
    ps_memory_set_drawing_policy();
    void *big = malloc(8u << 20);
    assert_non_null(big);
    free(big);
    size_t before = mallinfo2().hblks;
    void *mid = malloc(1u << 20);
    assert_non_null(mid);
    size_t after = mallinfo2().hblks;
    free(mid);
    assert_int_equal(after, before + 1);
    /* 16 MiB of 64 KiB blocks, as llvmpipe's bins, freed top down: kept. */
    enum { BLOCKS = 256, BLOCK = 64 << 10 };
    static void *blocks[BLOCKS];
    for (int i = 0; i < BLOCKS; i++) {
        blocks[i] = malloc(BLOCK);
        assert_non_null(blocks[i]);
        memset(blocks[i], 1, BLOCK);
    }
    for (int i = BLOCKS - 1; i >= 0; i--)
        free(blocks[i]);
    assert_true(mallinfo2().keepcost >= (size_t)BLOCKS * BLOCK * 3 / 4);
#else
    skip();
#endif
}

#if defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
/* The VmFlags of the mapping that holds p, from /proc/self/smaps ("" when
 * not found). */
static void vm_flags_of(const void *p, char *out, size_t size)
{
    out[0] = '\0';
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f)
        return;
    char line[512];
    bool in = false;
    uintptr_t at = (uintptr_t)p;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && strchr(line, '-') < strchr(line, ' ')) {
            in = at >= lo && at < hi;
            continue;
        }
        if (in && strncmp(line, "VmFlags:", 8) == 0) {
            snprintf(out, size, "%s", line + 8);
            break;
        }
    }
    fclose(f);
}
#endif

/* ps_memory_large_realloc: growth keeps the contents through every step,
 * from malloc's sizes into mappings of their own; a large array starts at a
 * 2 MiB boundary and its mapping is advised for huge pages (VmFlags "hg"),
 * after each growth (not under ASan, where the arrays are
 * malloc's). */
static void large_arrays(void **state)
{
    (void)state;
    size_t cap = 0;
    unsigned char *a = NULL;
    const size_t sizes[] = {100, 1u << 20, PS_MEMORY_LARGE_MIN, 3 * PS_MEMORY_LARGE_MIN + 12345,
                            8 * PS_MEMORY_LARGE_MIN};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        unsigned char *q = ps_memory_large_realloc(a, cap, sizes[k]);
        assert_non_null(q);
        for (size_t i = 0; i < cap; i += 4093)
            assert_int_equal(q[i], (unsigned char)(i * 7 + 1));
        for (size_t i = 0; i < sizes[k]; i++)
            q[i] = (unsigned char)(i * 7 + 1);
        a = q;
        cap = sizes[k];
#if defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
        if (cap >= PS_MEMORY_LARGE_MIN) {
            assert_int_equal((uintptr_t)a % (2u << 20), 0);
            char flags[512];
            vm_flags_of(a, flags, sizeof flags);
            /* (a kernel without huge pages refuses the advice) */
            if (access("/sys/kernel/mm/transparent_hugepage/enabled", F_OK) == 0 && !strstr(flags, " hg"))
                fail_msg("a large array of %zu bytes: VmFlags%s", cap, flags);
        }
#endif
    }
    /* the same size again: the same array */
    assert_ptr_equal(ps_memory_large_realloc(a, cap, cap), a);
    ps_memory_large_free(a, cap);
    ps_memory_large_free(NULL, 0);
}

/* ps_memory_reserve_large_heap: the heap grown at once by what was asked,
 * clamped to a quarter of the memory budget (256 MiB here, so 64 of the
 * 1024 asked), kept at its top (glibc's releasable top, keepcost); a 16 MiB
 * block then comes from the heap, not a mapping of its own (glibc's mapped
 * blocks), inside the part advised for huge pages (VmFlags "hg"). */
static void large_heap(void **state)
{
    (void)state;
#if defined(__GLIBC__) && defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
    const size_t mib = (size_t)1 << 20;
    setenv(PS_MEMORY_LIMIT_ENV, "256M", 1);
    ps_memory_reserve_large_heap(1024 * mib);
    unsetenv(PS_MEMORY_LIMIT_ENV);
    size_t kept = mallinfo2().keepcost;
    assert_true(kept >= 64 * mib);
    assert_true(kept < 128 * mib); /* clamped: not the 1 GiB asked */
    size_t mapped = mallinfo2().hblks;
    unsigned char *b = malloc(16 * mib);
    assert_non_null(b);
    assert_int_equal(mallinfo2().hblks, mapped);
    memset(b, 1, 16 * mib);
    char flags[512];
    vm_flags_of(b + 8 * mib, flags, sizeof flags);
    if (access("/sys/kernel/mm/transparent_hugepage/enabled", F_OK) == 0 && !strstr(flags, " hg"))
        fail_msg("a block from the reserved heap: VmFlags%s", flags);
    free(b);
    ps_memory_set_drawing_policy(); /* the other tests' allocator as before */
#else
    skip();
#endif
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(vector_algebra),
        cmocka_unit_test(basis_is_orthonormal),
        cmocka_unit_test(aabb_slab_test),
        cmocka_unit_test(transforms),
        cmocka_unit_test(strict_numbers),
        cmocka_unit_test(atomic_output),
        cmocka_unit_test(read_file_limits),
        cmocka_unit_test(name_map),
        cmocka_unit_test(line_lengths),
        cmocka_unit_test(error_messages_are_one_line), cmocka_unit_test(errors_carry_their_line),
        cmocka_unit_test(memory_budget),
        cmocka_unit_test(drawing_policy),
        cmocka_unit_test(large_arrays),
        cmocka_unit_test(large_heap),
        cmocka_unit_test(output_checks),
        cmocka_unit_test(cancel_flag_across_threads), cmocka_unit_test(interrupt_flag),
        cmocka_unit_test(low_priority_thread),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
