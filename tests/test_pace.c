/* test_pace.c: when photosplat-snap starts a refresh for its checkpoints
 * (app/pace.h), as pure decisions on a simulated clock: the checkpoint's
 * frame lands within PS_PACE_MARGIN of its time when the prediction holds, a
 * refresh that would delay it waits, cube faces never ride in the frame a
 * checkpoint shows, and a checkpoint out of reach gets the next frame.
 * The regression this guards: a refresh started just before a checkpoint
 * carried a second of cube faces (or an 8-bit redraw of every photon) and
 * the checkpoint landed a whole refresh late. */
#include "test.h"

#include "app/pace.h"

/* Runs refreshes on a simulated clock from `now` until a frame ends at or
 * after `cp` (the frame the checkpoint shows), each taking the model's
 * prediction times `error` plus `faces` seconds of cube faces when its plan
 * allows them (those that fit before the plan's faces deadline); photons
 * arrive at the model's rate. Returns when that frame ended; *faces_in_cp:
 * whether it carried faces. */
static double land(ps_pace_model m, double now, double photons, double tau, double cp, double error, double faces,
                   bool *faces_in_cp)
{
    double due = now;
    bool whole = m.per_photon > 0.0;
    for (int i = 0; i < 10000; i++) {
        ps_pace_plan p = ps_pace_next(&m, now, photons, due, &cp, 1);
        assert_true(p.start >= now);
        photons += m.rate * (p.start - now);
        double d = ps_pace_seconds(&m, photons) * error;
        bool with_faces = p.start + m.lead + faces <= p.faces_deadline;
        double end = p.start + (with_faces ? faces : 0.0) + d;
        /* The refresh measured: the model learns it (faces apart). */
        ps_pace_learn(&m, d, photons, whole);
        photons += m.rate * (end - p.start);
        now = end;
        due = fmax(due + tau, p.start);
        if (end >= cp) {
            *faces_in_cp = with_faces;
            return end;
        }
    }
    fail_msg("no frame reached the checkpoint");
    return 0.0;
}

/* 8 bits: whole refreshes whose time grows with the photons (0.4 s for a
 * million, a million a second): the 5 s checkpoint lands within the margin
 * instead of up to a refresh late. */
static void whole_refreshes_land_on_time(void **state)
{
    (void)state;
    ps_pace_model m = {0.4, 1e6, 0.4e-6, 1e6, 0.1};
    bool faces = true;
    double at = land(m, 1.0, 1e6, 0.1, 5.0, 1.0, 0.5, &faces);
    assert_true(at >= 5.0);
    assert_true(at <= 5.0 * 1.2); /* bench's goal: within 20 % */
    assert_false(faces);
    /* The refresh time grows 10 % faster than predicted: still within. */
    at = land(m, 1.0, 1e6, 0.1, 5.0, 1.1, 0.5, &faces);
    assert_true(at >= 5.0 && at <= 5.0 * 1.2);
}

/* Float: cheap incremental refreshes every tau. Cube faces run while the
 * checkpoint's frame still ends within PS_PACE_FACES_LATE of it, whatever
 * they cost; 0.6 s ones never fit: they wait, never in the checkpoint's
 * frame, which then lands a refresh's time after it. */
static void faces_wait_for_the_checkpoint(void **state)
{
    (void)state;
    ps_pace_model m = {0.05, 0.0, 0.0, 0.0, 0.01};
    for (double start = 0.5; start < 1.0; start += 0.05) {
        bool faces = true;
        double at = land(m, start, 0.0, 0.1, 1.0, 1.0, 0.6, &faces);
        assert_false(faces);
        assert_true(at >= 1.0 && at <= 1.0 + 0.05 * (1.0 + PS_PACE_MARGIN) + 1e-9);
        for (double f = 0.02; f < 0.6; f *= 2.0) {
            at = land(m, start, 0.0, 0.1, 1.0, 1.0, f, &faces);
            assert_true(at >= 1.0 && at <= 1.0 + PS_PACE_FACES_LATE + 1e-9);
        }
    }
    /* Far from the checkpoint, faces go as before. */
    double cp = 5.0;
    ps_pace_plan p = ps_pace_next(&m, 1.0, 0.0, 1.0, &cp, 1);
    assert_near(p.start, 1.0, 1e-12);
    assert_true(p.faces_deadline > 4.0);
}

/* A refresh that would end after the checkpoint's frame should start waits
 * for that start instead; one that ends before it goes at once. */
static void a_refresh_in_the_way_waits(void **state)
{
    (void)state;
    ps_pace_model m = {0.5, 0.0, 0.0, 0.0, 0.2};
    double cp = 1.0;
    ps_pace_plan p = ps_pace_next(&m, 0.3, 0.0, 0.3, &cp, 1);
    double ideal = cp + PS_PACE_MARGIN * 0.5 - 0.5;
    assert_near(p.start, ideal, 1e-12);
    assert_true(p.faces_deadline <= p.start); /* the margin is past 10 % of 1 s */
    p = ps_pace_next(&m, 0.0, 0.0, 0.0, &cp, 1);
    assert_near(p.start, 0.0, 1e-12);
    assert_near(p.faces_deadline, ideal - 0.5 + 0.2, 1e-12); /* the faces come after the lead */
}

/* A checkpoint out of reach (its frame cannot start before its ideal
 * start): that frame at once, no faces in it. Nothing known yet or no
 * checkpoint left: tau's schedule, faces unlimited. */
static void out_of_reach_and_defaults(void **state)
{
    (void)state;
    ps_pace_model m = {0.6, 0.0, 0.0, 0.0, 0.0};
    double cps[3] = {0.5, 1.0, 2.0};
    ps_pace_plan p = ps_pace_next(&m, 0.4, 0.0, 0.4, cps, 3);
    assert_int_equal(p.target, 0);
    assert_near(p.start, 0.4, 1e-12);
    assert_true(p.faces_deadline <= p.start);
    ps_pace_model none = {0.0, 0.0, 0.0, 0.0, 0.0};
    p = ps_pace_next(&none, 0.05, 0.0, 0.1, cps, 3);
    assert_near(p.start, 0.1, 1e-12);
    assert_false(isfinite(p.faces_deadline));
    p = ps_pace_next(&m, 0.05, 0.0, 0.1, cps, 0);
    assert_near(p.start, 0.1, 1e-12);
    assert_false(isfinite(p.faces_deadline));
}

/* The photon's cost is fitted from two whole refreshes, not the time
 * scaled by the photons (the first frame, mostly the direct layer, made
 * that predict 20 times too long); incremental ones cost a constant. */
static void learning(void **state)
{
    (void)state;
    ps_pace_model m = {0.0, 0.0, 0.0, 0.0, 0.0};
    ps_pace_learn(&m, 0.3, 2e4, true);
    assert_near(ps_pace_seconds(&m, 4e5), 0.3, 1e-12);
    ps_pace_learn(&m, 0.5, 4e5, true);
    assert_near(ps_pace_seconds(&m, 9e5), 0.5 + 0.2 / 3.8e5 * 5e5, 1e-9);
    ps_pace_learn(&m, 0.52, 4.1e5, true); /* too close to fit: the cost kept */
    assert_near(m.per_photon, 0.2 / 3.8e5, 1e-15);
    ps_pace_learn(&m, 0.1, 9e5, false);
    assert_near(ps_pace_seconds(&m, 5e6), 0.1, 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(whole_refreshes_land_on_time),
        cmocka_unit_test(faces_wait_for_the_checkpoint),
        cmocka_unit_test(a_refresh_in_the_way_waits),
        cmocka_unit_test(out_of_reach_and_defaults),
        cmocka_unit_test(learning),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
