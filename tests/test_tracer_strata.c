/* test_tracer_strata.c: per-stratum photon streams (tracer.h, issue 18).
 * Photon (stratum, j) is the same path whatever the other strata's shares:
 * after a power edit of one of two lights every photon's path is one of the
 * unedited scene's, at another index, and its bytes are that photon's with
 * its power set anew (ps_tracer_repower): equal, all 20 bytes. */
#include "test.h"
#include "rig.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "photon/tracer.h"
#include "two_lights.h"

#define N_CAUSTIC 6000
#define N_GLOBAL 3000

static const char *scene_text(char *buf, size_t size, const char *spot_power)
{
    snprintf(buf, size, TWO_LIGHTS_SCENE "%s\n", spot_power);
    return buf;
}

typedef struct traced {
    ps_photon_map map;
    ps_path_store paths;
    size_t *off; /* off[i]: index i's first photon in map */
} traced;

static traced trace(rig *r, ps_map_kind k, uint64_t n)
{
    traced t;
    ps_photon_map_init(&t.map, k);
    ps_path_store_init(&t.paths);
    ps_traced *tr;
    ps_error err;
    assert_int_equal(ps_tracer_trace_range(r->tracer, k, 0, n, n, 0, &tr, &err), PS_OK);
    assert_int_equal(ps_traced_join_paths(tr, &t.paths, NULL, &err), PS_OK);
    assert_int_equal(ps_traced_join(tr, &t.map, &err), PS_OK);
    ps_traced_destroy(tr);
    assert_int_equal(t.paths.count, n);
    assert_int_equal(t.paths.tcount, t.map.count);
    t.off = malloc((n + 1) * sizeof *t.off);
    t.off[0] = 0;
    for (uint64_t i = 0; i < n; i++)
        t.off[i + 1] = t.off[i] + t.paths.rec[i].stored;
    assert_int_equal(t.off[n], t.map.count);
    return t;
}

static void traced_free(traced *t)
{
    ps_photon_map_free(&t->map);
    ps_path_store_free(&t->paths);
    free(t->off);
}

/* frac: the fraction of n expected to match from the shares (0: not known
 * in closed form). */
static void one_map(rig *a, rig *b, ps_map_kind k, uint64_t n, double frac)
{
    traced ta = trace(a, k, n), tb = trace(b, k, n);
    ps_photon_source *src = malloc(n * sizeof *src);
    bool resampled[2] = {false, false};
    ps_error err;
    assert_int_equal(ps_tracer_photon_sources(a->tracer, b->tracer, k, n, n, resampled, 2, src, &err), PS_OK);
    /* The expected number of matches: per stratum, the fewer of its two counts. */
    uint64_t expect = 0;
    for (uint32_t l = 0; l < 2; l++)
        for (int64_t target = -1; target < 7; target++) {
            uint64_t na = ps_tracer_stratum_photons(a->tracer, k, l, target, n);
            uint64_t nb = ps_tracer_stratum_photons(b->tracer, k, l, target, n);
            expect += na < nb ? na : nb;
        }
    uint64_t matched = 0, moved = 0, photons = 0;
    for (uint64_t i = 0; i < n; i++) {
        if (src[i].from == PS_SOURCE_NONE)
            continue;
        matched++;
        moved += src[i].from != i;
        uint64_t o = src[i].from;
        size_t na = ta.paths.rec[o].stored, nb = tb.paths.rec[i].stored;
        assert_int_equal(na, nb);
        assert_int_equal(ta.paths.rec[o].vertices, tb.paths.rec[i].vertices);
        /* The same path: every photon the same but for its power. */
        ps_photon *pa = malloc((na ? na : 1) * sizeof *pa);
        memcpy(pa, ta.map.photons + ta.off[o], na * sizeof *pa);
        ps_tracer_repower(b->tracer, k, &src[i], ta.paths.thr + ta.off[o], na, pa);
        assert_memory_equal(pa, tb.map.photons + tb.off[i], na * sizeof *pa);
        assert_memory_equal(ta.paths.thr + ta.off[o], tb.paths.thr + tb.off[i], na * sizeof(ps_path_thr));
        assert_memory_equal(ta.map.materials + ta.off[o], tb.map.materials + tb.off[i], na * sizeof(uint16_t));
        assert_memory_equal(ta.map.objects + ta.off[o], tb.map.objects + tb.off[i], na * sizeof(uint32_t));
        photons += na;
        free(pa);
    }
    fprintf(stderr, "%s: %llu of %llu photon paths are the unedited scene's (%llu at another index), %llu photons\n",
            ps_map_name(k), (unsigned long long)matched, (unsigned long long)n, (unsigned long long)moved,
            (unsigned long long)photons);
    assert_int_equal(matched, expect);
    /* All but the counts' growth: a low-discrepancy share is within a few
     * photons of n times the share, for every n. */
    if (frac > 0.0)
        assert_true(fabs((double)expect - frac * (double)n) <= 4.0);
    assert_true(expect > n / 2);
    assert_true(moved > 0);           /* the shares did change */
    assert_true(photons > 0);
    free(src);
    traced_free(&ta);
    traced_free(&tb);
}

/* A tracer that records paths, as a repairing session's. */
static ps_tracer_options record_options(void)
{
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 5;
    o.threads = 2;
    o.records = true;
    return o;
}

/* The spot twice as bright: both lights' shares change, no path does. */
static void paths_survive_a_share_change(void **state)
{
    (void)state;
    char ta[2048], tb[2048];
    ps_tracer_options o = record_options();
    rig a = rig_make(scene_text(ta, sizeof ta, "60 50 40"), "", &o, PS_ACCEL_AUTO);
    ps_aabb box = ps_scene_bounds(a.scene);
    box.lo = ps_v3_sub(box.lo, ps_v3(2, 2, 2));
    box.hi = ps_v3_add(box.hi, ps_v3(2, 2, 2));
    rig_free(&a);
    o.record_box = box;
    a = rig_make(scene_text(ta, sizeof ta, "60 50 40"), "", &o, PS_ACCEL_AUTO);
    rig b = rig_make(scene_text(tb, sizeof tb, "120 100 80"), "", &o, PS_ACCEL_AUTO);
    assert_true(ps_tracer_light_photons(a.tracer, PS_MAP_GLOBAL, 0, N_GLOBAL) !=
                ps_tracer_light_photons(b.tracer, PS_MAP_GLOBAL, 0, N_GLOBAL));
    /* Global: the point's share 300 / 450 = 2/3 becomes 1/2, the spot's
     * 1/3 becomes 1/2: 1/2 + 1/3 of the photons keep their paths. */
    one_map(&a, &b, PS_MAP_GLOBAL, N_GLOBAL, 5.0 / 6.0);
    one_map(&a, &b, PS_MAP_CAUSTIC, N_CAUSTIC, 0.0);
    rig_free(&a);
    rig_free(&b);
}

/* Each stratum's count over a prefix follows its share for every prefix
 * (the strata still interleave along the index), and the ranks the tracer
 * gives are 0.. in index order: photon sources of a tracer with itself name
 * every index itself. */
static void ranks_are_in_index_order(void **state)
{
    (void)state;
    char t[2048];
    ps_tracer_options o = ps_tracer_default_options();
    o.seed = 9;
    o.threads = 1;
    rig a = rig_make(scene_text(t, sizeof t, "60 50 40"), "", &o, PS_ACCEL_AUTO);
    const uint64_t n = 5000;
    ps_photon_source *src = malloc(n * sizeof *src);
    bool resampled[2] = {false, false};
    ps_error err;
    assert_int_equal(ps_tracer_photon_sources(a.tracer, a.tracer, PS_MAP_CAUSTIC, n, n, resampled, 2, src, &err),
                     PS_OK);
    uint64_t next[16] = {0};
    for (uint64_t i = 0; i < n; i++) {
        assert_int_equal(src[i].from, i);
        assert_true(src[i].stratum < 16);
        assert_int_equal(src[i].rank, next[src[i].stratum]++);
    }
    /* The spot resampled (moved): its strata match nothing, the point's all. */
    resampled[1] = true;
    assert_int_equal(ps_tracer_photon_sources(a.tracer, a.tracer, PS_MAP_CAUSTIC, n, n, resampled, 2, src, &err),
                     PS_OK);
    uint64_t none = 0;
    for (uint64_t i = 0; i < n; i++)
        none += src[i].from == PS_SOURCE_NONE;
    uint64_t spot = ps_tracer_light_photons(a.tracer, PS_MAP_CAUSTIC, 1, n);
    assert_true(spot > 0);
    assert_int_equal(none, spot);
    free(src);
    rig_free(&a);
}

static void same_source(const ps_photon_source *x, const ps_photon_source *y, uint64_t i)
{
    if (x->from != y->from || x->rank != y->rank || x->stratum != y->stratum || x->repower != y->repower)
        fail_msg("photon %llu: from %llu rank %llu stratum %u repower %d against %llu %llu %u %d",
                 (unsigned long long)i, (unsigned long long)x->from, (unsigned long long)x->rank, x->stratum,
                 x->repower, (unsigned long long)y->from, (unsigned long long)y->rank, y->stratum, y->repower);
}

/* sources in ranges that start and end anywhere (not on the rank table's
 * rows) against the whole at once */
static void fill_in_parts(ps_source_map *m, const ps_photon_source *whole, uint64_t n)
{
    const uint64_t cuts[] = {0, 1, 255, 256, 257, 1000, 4097, n - 1, n};
    ps_photon_source *part = malloc(n * sizeof *part);
    for (size_t c = 0; c + 1 < sizeof cuts / sizeof *cuts; c++) {
        ps_source_map_fill(m, cuts[c], cuts[c + 1], part);
        for (uint64_t i = cuts[c]; i < cuts[c + 1]; i++)
            same_source(&part[i - cuts[c]], &whole[i], i);
    }
    free(part);
}

/* The sources a repair finds a step at a time (ps_source_map) are the
 * whole table's in any ranges; an edit that keeps the shares (the same
 * scene on a new tracer) names every photon itself (identity: the repair
 * keeps them in place) with b's rank table copied from a's, and b then
 * traces a's photons byte for byte; an edit that changes the shares does
 * not; one that resamples every light keeps nothing (none: a restart). */
static void sources_in_parts(void **state)
{
    (void)state;
    char ta[2048], tb[2048];
    ps_tracer_options o = record_options();
    rig a = rig_make(scene_text(ta, sizeof ta, "60 50 40"), "", &o, PS_ACCEL_AUTO);
    rig b = rig_make(scene_text(tb, sizeof tb, "120 100 80"), "", &o, PS_ACCEL_AUTO);
    rig same = rig_make(scene_text(tb, sizeof tb, "60 50 40"), "", &o, PS_ACCEL_AUTO);
    const uint64_t n = N_CAUSTIC;
    bool resampled[2] = {false, false};
    ps_photon_source *whole = malloc(n * sizeof *whole);
    ps_error err;
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        /* the shares changed: not in place, some kept */
        ps_source_map *m;
        assert_int_equal(ps_tracer_photon_sources(a.tracer, b.tracer, k, n, n, resampled, 2, whole, &err), PS_OK);
        assert_int_equal(ps_source_map_create(a.tracer, b.tracer, k, n, n, resampled, 2, &m, &err), PS_OK);
        assert_false(ps_source_map_identity(m));
        assert_false(ps_source_map_none(m));
        fill_in_parts(m, whole, n);
        ps_source_map_destroy(m);
        /* every light resampled: nothing kept */
        bool all[2] = {true, true};
        assert_int_equal(ps_source_map_create(a.tracer, b.tracer, k, n, n, all, 2, &m, &err), PS_OK);
        assert_true(ps_source_map_none(m));
        ps_source_map_fill(m, 0, n, whole);
        for (uint64_t i = 0; i < n; i++)
            assert_true(whole[i].from == PS_SOURCE_NONE);
        ps_source_map_destroy(m);
    }
    for (int k = 0; k < PS_MAP_COUNT; k++) {
        /* the same shares, b not yet counted: copied from a */
        ps_source_map *m;
        assert_int_equal(ps_source_map_create(a.tracer, same.tracer, k, n, n, resampled, 2, &m, &err), PS_OK);
        assert_true(ps_source_map_identity(m));
        assert_false(ps_source_map_none(m));
        /* the table of a tracer with itself, counted from index 0 */
        assert_int_equal(ps_tracer_photon_sources(a.tracer, a.tracer, k, n, n, resampled, 2, whole, &err), PS_OK);
        fill_in_parts(m, whole, n);
        ps_source_map_destroy(m);
        traced x = trace(&a, k, n), y = trace(&same, k, n);
        assert_int_equal(x.map.count, y.map.count);
        assert_memory_equal(x.map.photons, y.map.photons, x.map.count * sizeof *x.map.photons);
        traced_free(&x);
        traced_free(&y);
    }
    free(whole);
    rig_free(&a);
    rig_free(&b);
    rig_free(&same);
}

/* Lights past the two, so that the caustic map has a dozen strata with
 * cuts everywhere. */
#define MORE_LIGHTS                                                       \
    "light point position -0.5 1.8 0 power 7 7 7\n"                      \
    "light point position 0.2 1.7 -0.5 power 30 20 10\n"                 \
    "light point position 0.6 1.8 0.6 power 0.5 0.5 0.5\n"
#define WALK_LIGHTS 5
#define WALK_STRATA 64

/* The index whose choice of stratum reads m: Halton dimension 0 is the
 * reversal of an index's low 53 bits. */
static uint64_t index_of_m(uint64_t m)
{
    uint64_t i = 0;
    for (int b = 0; b < 53; b++)
        i |= ((m >> b) & 1) << (52 - b);
    return i;
}

static uint32_t stratum_at_m(rig *a, ps_map_kind k, uint64_t m, uint64_t *rank)
{
    uint32_t s;
    uint64_t r;
    assert_true(ps_tracer_photon_rank(a->tracer, k, index_of_m(m), (uint64_t)1 << 54, &s, &r));
    if (rank)
        *rank = r;
    return s;
}

/* Index i (far out, choice m) is counted in its own stratum: the next index
 * of that stratum ranks one above it. */
static void counted_in_own_stratum(rig *a, ps_map_kind k, uint64_t m)
{
    uint64_t i = index_of_m(m), rank, next_rank;
    uint32_t s = stratum_at_m(a, k, m, &rank), t;
    for (uint64_t j = i + 1;; j++) {
        assert_true(ps_tracer_photon_rank(a->tracer, k, j, (uint64_t)1 << 54, &t, &next_rank));
        if (t == s)
            break;
        assert_true(j - i < 100000);
    }
    if (next_rank != rank + 1)
        fail_msg("m %llu (index %llu): stratum %u, rank %llu; its next photon ranks %llu", (unsigned long long)m,
                 (unsigned long long)i, s, (unsigned long long)rank, (unsigned long long)next_rank);
}

/* The strata's cuts found from outside, exactly: where the stratum of m
 * changes along a grid of 4096 m, bisected to the m where it changes; both
 * indices beside each cut are counted in their own strata. */
static int cuts_counted_exactly(rig *a, ps_map_kind k)
{
    enum { GRID_BITS = 12 };
    const uint64_t step = (uint64_t)1 << (53 - GRID_BITS);
    int cuts = 0;
    uint32_t prev = stratum_at_m(a, k, 0, NULL);
    for (uint64_t g = 1; g <= (uint64_t)1 << GRID_BITS; g++) {
        uint64_t hi = g == (uint64_t)1 << GRID_BITS ? ((uint64_t)1 << 53) - 1 : g * step;
        uint32_t here = stratum_at_m(a, k, hi, NULL);
        if (here != prev) {
            uint64_t lo = (g - 1) * step; /* stratum(lo) != stratum(hi): the first m after lo that differs */
            while (hi - lo > 1) {
                uint64_t mid = lo + (hi - lo) / 2;
                if (stratum_at_m(a, k, mid, NULL) == prev)
                    lo = mid;
                else
                    hi = mid;
            }
            counted_in_own_stratum(a, k, lo);
            counted_in_own_stratum(a, k, hi);
            cuts++;
        }
        prev = here;
    }
    return cuts;
}

/* The photons of each light below index n, walked: lights[l] below `at`. */
static void walk_far(rig *a, ps_map_kind k, uint64_t n0)
{
    enum { WALK = 3000 };
    uint64_t lights[WALK_LIGHTS] = {0}, sum = 0;
    for (uint32_t l = 0; l < WALK_LIGHTS; l++)
        sum += lights[l] = ps_tracer_light_photons(a->tracer, k, l, n0);
    assert_true(sum == n0);
    uint64_t next[WALK_STRATA];
    bool seen[WALK_STRATA] = {false};
    for (uint64_t i = n0; i < n0 + WALK; i++) {
        uint32_t s;
        uint64_t rank;
        assert_true(ps_tracer_photon_rank(a->tracer, k, i, n0 + WALK, &s, &rank));
        assert_true(s < WALK_STRATA);
        /* consecutive photons of a stratum: ranks one apart */
        if (seen[s] && rank != next[s])
            fail_msg("index %llu: rank %llu, %llu expected", (unsigned long long)i, (unsigned long long)rank,
                     (unsigned long long)next[s]);
        seen[s] = true;
        next[s] = rank + 1;
        lights[ps_tracer_photon_light(a->tracer, k, i, n0 + WALK)]++;
    }
    for (uint32_t l = 0; l < WALK_LIGHTS; l++)
        assert_true(ps_tracer_light_photons(a->tracer, k, l, n0 + WALK) == lights[l]);
}

/* Each stratum's photons below an index come in closed form, from where the
 * cuts between strata fall (tracer.c, count_below), not from a walk over
 * every index: against such a walk, for three seeds (the choice's rotation)
 * and three shares, the rank of every index below 2^16 + 1000 is its
 * stratum's photons below it, and each light's photons below n are those
 * counted, at n on and beside powers of two and every 997th; far out (n
 * about 2^40 and 2^54, past the 53 bits of the choice) they add up to n and
 * a walk of 3000 indices agrees with the counts at both ends; and the
 * indices beside every cut (found from outside) are counted exactly. */
static void counts_in_closed_form(void **state)
{
    (void)state;
    enum { N = (1 << 16) + 1000 };
    static const char *const spot[] = {"60 50 40", "1 1 1", "300 300 300"};
    for (uint64_t seed = 0; seed < 3; seed++)
        for (size_t p = 0; p < sizeof spot / sizeof *spot; p++) {
            char t[4096];
            snprintf(t, sizeof t, TWO_LIGHTS_SCENE "%s\n" MORE_LIGHTS, spot[p]);
            ps_tracer_options o = ps_tracer_default_options();
            o.seed = seed;
            o.threads = 1;
            rig a = rig_make(t, "", &o, PS_ACCEL_AUTO);
            for (int k = 0; k < PS_MAP_COUNT; k++) {
                uint64_t below[WALK_STRATA] = {0}, lights[WALK_LIGHTS] = {0};
                for (uint64_t i = 0; i < N; i++) {
                    uint32_t s;
                    uint64_t rank;
                    assert_true(ps_tracer_photon_rank(a.tracer, (ps_map_kind)k, i, N, &s, &rank));
                    assert_true(s < WALK_STRATA);
                    if (rank != below[s])
                        fail_msg("seed %llu, map %d, index %llu: rank %llu, %llu walked",
                                 (unsigned long long)seed, k, (unsigned long long)i, (unsigned long long)rank,
                                 (unsigned long long)below[s]);
                    below[s]++;
                    uint32_t l = ps_tracer_photon_light(a.tracer, (ps_map_kind)k, i, N);
                    assert_true(l < WALK_LIGHTS);
                    lights[l]++;
                    uint64_t n = i + 1;
                    bool beside_power = ((n - 1) & (n - 2)) == 0 || (n & (n - 1)) == 0 || ((n + 1) & n) == 0;
                    if (beside_power || n % 997 == 0 || n == N)
                        for (uint32_t m = 0; m < WALK_LIGHTS; m++)
                            assert_true(ps_tracer_light_photons(a.tracer, (ps_map_kind)k, m, n) == lights[m]);
                }
                walk_far(&a, (ps_map_kind)k, ((uint64_t)1 << 40) + 123457);
                walk_far(&a, (ps_map_kind)k, ((uint64_t)1 << 54) + 99991);
                /* the caustic map: a dozen strata, the global one five */
                assert_true(cuts_counted_exactly(&a, (ps_map_kind)k) >= (k == PS_MAP_GLOBAL ? 4 : 8));
            }
            rig_free(&a);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(paths_survive_a_share_change),
        cmocka_unit_test(ranks_are_in_index_order),
        cmocka_unit_test(sources_in_parts),
        cmocka_unit_test(counts_in_closed_form),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
