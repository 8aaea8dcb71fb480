/* test_gl_8bit.c: the thesis' 8-bit colour buffer (5.1) with the accurate
 * splats, through the preview session and OSMesa: the mirror-quad caustic
 * (the tracer tests' closed form) drawn by kernel-textured triangles and
 * sprites into an 8-bit buffer with error diffusion keeps its light, pixel by
 * pixel, where the smooth kernel's faint fragments rounded away. */
#include "test.h"
#include "analytic.h"

#include <GL/osmesa.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl_render.h"
#include "preview/session.h"
#include "scene/scene.h"

#define SCENE "tests/data/good/mirror-caustic.scn"
#define SIDE 64
/* Keeps the caustic (0.14 W sr^-1 m^-2 under the mirror) at about 0.7 of
 * white: the codes a designer would see it with. */
#define EXPOSURE 5.0
/* Pixels seeing the floor within this of the axis (the lit square's half
 * side is 1.5): sprites themselves, in a float buffer too, lose up to 5 %
 * nearer its edge at this oblique view (docs/preview.md), which is no part
 * of the 8-bit handling measured here. */
#define LIM 0.8



typedef struct rig8 {
    ps_scene *scene;
    ps_session *session;
    OSMesaContext ctx;
    void *buffer;
    ps_gl_renderer *gl;
    ps_camera_frame cam;
} rig8;

static void rig_open(rig8 *r, ps_splat_mode mode, uint64_t photons, bool float_buffer)
{
    memset(r, 0, sizeof *r);
    ps_error err;
    if (ps_scene_load(SCENE, NULL, &r->scene, &err) != PS_OK)
        fail_msg("scene: %s", err.msg);
    ps_session_settings set = ps_session_default_settings(r->scene);
    set.layers = PS_LAYER_CAUSTIC;
    set.skip_hidden = true;
    set.splat = mode;
    set.float_buffer = float_buffer;
    set.precision = PS_PRECISION_DIFFUSION;
    set.exposure = EXPOSURE;
    set.threads = 2;
    if (photons)
        set.caps[PS_MAP_CAUSTIC] = photons;
    if (ps_session_create(r->scene, &set, &r->session, &err) != PS_OK)
        fail_msg("session: %s", err.msg);
    assert_int_equal(ps_session_trace_all(r->session, &err), PS_OK);
    r->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
    assert_non_null(r->ctx);
    r->buffer = malloc(4 * sizeof(float) * SIDE * SIDE);
    assert_true(OSMesaMakeCurrent(r->ctx, r->buffer, float_buffer ? GL_FLOAT : GL_UNSIGNED_BYTE, SIDE, SIDE));
    ps_gl_options go = {false, float_buffer, 0, false, false, OSMesaGetProcAddress};
    ps_gl_scene gs = ps_gl_scene_of(r->session);
    assert_int_equal(ps_gl_renderer_create(&gs, ps_session_kernel(r->session), &go, &r->gl, &err), PS_OK);
    r->cam = ps_camera_frame_make(ps_scene_camera(r->scene), SIDE, SIDE);
}

static void rig_close(rig8 *r)
{
    ps_gl_renderer_destroy(r->gl);
    OSMesaDestroyContext(r->ctx);
    free(r->buffer);
    ps_session_destroy(r->session);
    ps_scene_destroy(r->scene);
}

/* The session's refresh drawn whole into the 8-bit buffer, read back as
 * radiance (the codes / 255 / exposure). */
static ps_image draw(rig8 *r)
{
    ps_session_frame f;
    ps_error err;
    assert_int_equal(ps_session_refresh(r->session, &r->cam, &f, &err), PS_OK);
    ps_gl_draw_frame(r->gl, &r->cam, &f);
    ps_image img;
    assert_int_equal(ps_gl_read(r->gl, &img, &err), PS_OK);
    for (size_t i = 0; i < 3 * (size_t)SIDE * SIDE; i++)
        img.rgb[i] /= (float)EXPOSURE;
    return img;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Pixels seeing the floor well inside the lit square (|x|, |z| < LIM):
 * the mean of got / expected and the median of |got / expected - 1|. */
static void against_closed_form(const rig8 *r, const ps_image *img, double *mean, double *median, int *count)
{
    static double err[SIDE * SIDE];
    double intensity = 100.0 / (4.0 * PS_PI), sum = 0.0;
    int n = 0;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            ps_vec3 q;
            if (!floor_point(&r->cam, x + 0.5, y + 0.5, &q) || fabs(q.x) > LIM || fabs(q.z) > LIM)
                continue;
            double expect = floor_radiance(0.5, intensity, 3.0, 0.0, 0.0, q);
            double ratio = ps_image_at(img, x, y)[1] / expect;
            sum += ratio;
            err[n++] = fabs(ratio - 1.0);
        }
    qsort(err, (size_t)n, sizeof *err, cmp_double);
    *mean = sum / n;
    *median = err[n / 2];
    *count = n;
}

/* At the scene's own photon count: mean within 2 % and the median pixel
 * within 5 % of the closed form, for triangles and sprites. The smooth
 * kernel the halftone replaced, drawn the same way, shows what was lost. */
static void caustic_keeps_its_light(void **state)
{
    (void)state;
    const ps_splat_mode modes[2] = {PS_SPLAT_TRIANGLES, PS_SPLAT_SPRITES};
    for (int m = 0; m < 2; m++) {
        rig8 r;
        /* The yardstick: the float buffer, smooth kernel. */
        rig_open(&r, modes[m], 0, true);
        ps_image fimg = draw(&r);
        double fmean, fmedian;
        int n;
        against_closed_form(&r, &fimg, &fmean, &fmedian, &n);
        ps_image_destroy(&fimg);
        rig_close(&r);
        rig_open(&r, modes[m], 0, false);
        assert_true(ps_session_kernel(r.session)->halftone);
        ps_image img = draw(&r);
        double mean, median;
        against_closed_form(&r, &img, &mean, &median, &n);
        ps_image_destroy(&img);
        /* The smooth kernel in the same 8-bit buffer. */
        ps_kernel_texture smooth;
        ps_error err;
        assert_int_equal(ps_kernel_texture_make(ps_session_get_settings(r.session)->kernel, PS_KERNEL_TEXTURE_SIZE,
                                                &smooth, &err),
                         PS_OK);
        ps_gl_renderer_set_kernel(r.gl, &smooth);
        /* The splats' colours assume the halftone's C; rescale to the smooth one's. */
        ps_session_frame f;
        assert_int_equal(ps_session_refresh(r.session, &r.cam, &f, &err), PS_OK);
        ps_splat_batch *b = (ps_splat_batch *)f.map[PS_MAP_CAUSTIC].batch;
        double k = ps_session_kernel(r.session)->mean / smooth.mean;
        for (size_t i = 0; i < b->vertex_count; i++)
            for (int ch = 0; ch < 3; ch++)
                b->colors[4 * i + ch] *= (float)k;
        ps_gl_draw_frame(r.gl, &r.cam, &f);
        ps_image old;
        assert_int_equal(ps_gl_read(r.gl, &old, &err), PS_OK);
        for (size_t i = 0; i < 3 * (size_t)SIDE * SIDE; i++)
            old.rgb[i] /= (float)EXPOSURE;
        double old_mean, old_median;
        against_closed_form(&r, &old, &old_mean, &old_median, &n);
        printf("%s, %llu photons, of the closed form: float mean %.4f, median pixel %.2f %% off; 8-bit diffusion "
               "halftone %.4f, %.2f %%; the smooth kernel in 8 bits %.4f, %.2f %% (%d pixels)\n",
               ps_splat_mode_name(modes[m]), (unsigned long long)ps_session_get_settings(r.session)->caps[0], fmean,
               100 * fmedian, mean, 100 * median, old_mean, 100 * old_median, n);
        fflush(stdout);
        assert_true(n > 500);
        assert_near(mean, 1.0, 0.02);
        assert_true(median < 0.05);
        assert_near(mean, fmean, 0.01); /* the yardstick's own mean */
        assert_true(old_mean < 0.9);     /* what the halftone cures */
        ps_image_destroy(&old);
        ps_kernel_texture_free(&smooth);
        rig_close(&r);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(caustic_keeps_its_light),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
