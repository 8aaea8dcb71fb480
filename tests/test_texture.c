/* test_texture.c: map_Kd textures (scene/texture.h) and the albedo at a
 * surface point (ps_scene_albedo_at). Oracles: the sRGB decoding of the
 * file's codes; bilinear weights worked out by hand; the OBJ's vt mapping
 * (v = 0 the image's bottom row), repeat wrapping, Kd times the texture. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "scene/scene.h"
#include "scene/texture.h"

static double decode(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

/* A 2x2 PNG: top row codes 0 and 255 (red channel), bottom row 51 and 204. */
static const char *write_png(void)
{
    ps_image img;
    ps_error err;
    assert_int_equal(ps_image_create(2, 2, &img, &err), PS_OK);
    /* ps_png_write encodes linear values: give it the decoded codes. */
    const double codes[4] = {0, 255, 51, 204};
    for (int k = 0; k < 4; k++) {
        float *p = ps_image_at(&img, k % 2, k / 2);
        p[0] = p[1] = p[2] = (float)decode(codes[k] / 255.0);
    }
    const char *path = test_path("t.png");
    static char keep[1024];
    snprintf(keep, sizeof keep, "%s", path);
    assert_int_equal(ps_png_write(&img, keep, 1.0f, &err), PS_OK);
    ps_image_destroy(&img);
    return keep;
}

static void sampling(void **state)
{
    (void)state;
    ps_texture *t = NULL;
    ps_error err;
    assert_int_equal(ps_texture_load(write_png(), 0, &t, &err), PS_OK);
    assert_int_equal(ps_texture_width(t), 2);
    double top_left = 0.0, top_right = 1.0, bottom_left = decode(51 / 255.0), bottom_right = decode(204 / 255.0);
    /* Texel centres: u 0.25 / 0.75, v 0.75 (top row) / 0.25 (bottom row). */
    assert_near(ps_texture_sample(t, 0.25, 0.75).r, top_left, 1e-6);
    assert_near(ps_texture_sample(t, 0.75, 0.75).r, top_right, 1e-6);
    assert_near(ps_texture_sample(t, 0.25, 0.25).r, bottom_left, 1e-6);
    assert_near(ps_texture_sample(t, 0.75, 0.25).r, bottom_right, 1e-6);
    /* Repeat: whole numbers added change nothing; u = 0 lies halfway between
     * the last and the first texel of the row. */
    assert_near(ps_texture_sample(t, 3.25, -1.25).r, top_left, 1e-6);
    assert_near(ps_texture_sample(t, 0.0, 0.75).r, 0.5 * (top_left + top_right), 1e-6);
    /* Bilinear: a quarter of the way from the bottom-left centre to the right
     * and up: weights 3/4, 1/4 along each axis. */
    double want = 0.75 * (0.75 * bottom_left + 0.25 * bottom_right) + 0.25 * (0.75 * top_left + 0.25 * top_right);
    assert_near(ps_texture_sample(t, 0.375, 0.375).r, want, 1e-6);
    /* Not a number: no crash, a texel. */
    ps_rgb c = ps_texture_sample(t, NAN, INFINITY);
    assert_true(c.r >= 0.0 && c.r <= 1.0);
    ps_texture_unref(t);
    assert_int_not_equal(ps_texture_load(test_path("t.gif"), 0, &t, &err), PS_OK);
    assert_null(t);
}

/* An OBJ quad with vt and map_Kd, Kd 0.5: the albedo at points of its two
 * triangles, a clone sharing the texture, and a missing texture's warning. */
static void albedo_at_points(void **state)
{
    (void)state;
    write_png();
    FILE *fp = fopen(test_path("q.obj"), "wb");
    assert_non_null(fp);
    fputs("mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
          "usemtl t\nf 1/1 2/2 3/3 4/4\nusemtl gone\nf 1 3 4\n",
          fp);
    fclose(fp);
    fp = fopen(test_path("q.mtl"), "wb");
    assert_non_null(fp);
    fputs("newmtl t\nKd 0.5 0.5 0.5\nmap_Kd t.png\nnewmtl gone\nKd 0.25 0.25 0.25\nmap_Kd nothere.jpg\n", fp);
    fclose(fp);
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", test_path(""));
    dir[strlen(dir) - 1] = '\0';
    ps_scene *s = NULL;
    ps_error err;
    warn_log log = {0, ""};
    ps_scene_load_options opts = {{log_warning, &log}};
    if (ps_scene_load_text("camera eye 0 0 3 target 0 0 0\nmesh q.obj\nlight point position 0 0 1 power 1 1 1\n",
                           "t.scn", dir, &opts, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    assert_non_null(strstr(log.last, "nothere.jpg"));
    size_t nm, nt;
    const ps_material *m = ps_scene_materials(s, &nm);
    const ps_triangle *tri = ps_scene_triangles(s, &nt);
    assert_int_equal(nt, 3);
    assert_int_equal(ps_scene_texture_count(s), 1);
    const ps_material *tm = &m[tri[0].material], *gone = &m[tri[2].material];
    assert_int_equal(tm->texture, 1);
    assert_int_equal(gone->texture, 0);
    /* Triangle 0 is (v1, v2, v3): barycentric (b1, b2) is u = b1 + b2, v = b2.
     * The bottom-right texel's centre, (0.75, 0.25): b1 = 0.5, b2 = 0.25. */
    double bottom_right = decode(204 / 255.0);
    assert_near(ps_scene_albedo_at(s, tm, 0, 0.5, 0.25).r, 0.5 * bottom_right, 1e-6);
    /* Triangle 1 is (v1, v3, v4): u = b1, v = b1 + b2; the top-right centre
     * (0.75, 0.75): b1 = 0.75, b2 = 0. */
    assert_near(ps_scene_albedo_at(s, tm, 1, 0.75, 0.0).r, 0.5 * 1.0, 1e-6);
    /* No texture, or not on a triangle: Kd. */
    assert_near(ps_scene_albedo_at(s, gone, 2, 0.3, 0.3).r, 0.25, 0.0);
    assert_near(ps_scene_albedo_at(s, tm, UINT32_MAX, 0.3, 0.3).r, 0.5, 0.0);
    ps_scene *c = NULL;
    assert_int_equal(ps_scene_clone(s, &c, &err), PS_OK);
    assert_ptr_equal(ps_scene_texture(c, 0), ps_scene_texture(s, 0));
    uint32_t textured = tri[0].material;
    ps_scene_destroy(s); /* the clone keeps its reference */
    assert_near(ps_scene_albedo_at(c, &ps_scene_materials(c, NULL)[textured], 0, 0.5, 0.25).r, 0.5 * bottom_right,
                1e-6);
    ps_scene_destroy(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sampling),
        cmocka_unit_test(albedo_at_points),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
