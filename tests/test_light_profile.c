/* test_light_profile.c: the preview's lat-long intensity tables: largest
 * value 1, the flux they hold (sum of value * peak * solid angle = 1 per
 * watt) for every light type, values against the lights' own intensity, the
 * frame, and the 8-bit form. */
#include "test.h"

#include <stdlib.h>
#include <string.h>

#include "preview/light_profile.h"
#include "scene/ies.h"
#include "scene/scene.h"

static ps_scene *load(const char *text)
{
    ps_scene *s;
    ps_error err;
    if (ps_scene_load_text(text, "inline.scn", "", NULL, &s, &err) != PS_OK)
        fail_msg("%s", err.msg);
    return s;
}

static double held_flux(const ps_light_profile *p)
{
    double sum = 0;
    for (int j = 0; j < p->height; j++)
        for (int i = 0; i < p->width; i++)
            sum += p->texels[j * p->width + i] * p->peak * ps_light_profile_texel_solid_angle(p, j);
    return sum;
}

static void every_type_holds_its_flux(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0\n"
                       "light point position 0 1 0 power 1 1 1\n"
                       "light spot position 0 1 0 direction 0.3 -1 0.2 angle 25 power 1 1 1\n"
                       "light quad corner 0 2 0 edge1 0 0 1 edge2 1 0 0 power 1 1 1\n"
                       "light disc center 0 2 0 normal 1 -1 0 radius 0.1 power 1 1 1\n"
                       "light sphere center 0 1 0 radius 0.1 power 1 1 1\n"
                       "light ies data/ies/downlight-narrow.ies position 0 2 0\n"
                       "light ies data/ies/wallwasher.ies position 0 2 0 aim 0.2 -1 0.1 spin 30\n"
                       "light ies data/ies/batwing.ies position 0 2 0\n");
    size_t n;
    const ps_light *l = ps_scene_lights(s, &n);
    for (size_t k = 0; k < n; k++) {
        ps_light_profile p;
        ps_error err;
        assert_int_equal(ps_light_profile_make(s, k, 64, &p, &err), PS_OK);
        assert_int_equal(p.width, 128);
        float hi = 0;
        for (int t = 0; t < p.width * p.height; t++) {
            assert_true(p.texels[t] >= 0.0f && p.texels[t] <= 1.0f);
            hi = fmaxf(hi, p.texels[t]);
        }
        assert_true(hi == 1.0f);
        double flux = held_flux(&p);
        printf("%-6s: the table holds %.5f of the flux, peak %.5f /sr\n", ps_light_type_name(l[k].type), flux, p.peak);
        assert_near(flux, 1.0, 0.005);
        /* The value towards a texel's centre direction times the peak is
         * the light's own intensity there, within the texel's averaging. */
        if (l[k].type == PS_LIGHT_IES) {
            const ps_ies *ies = ps_scene_ies_profile(s, l[k].profile);
            for (int j = 1; j < p.height; j += 7) {
                double th = (j + 0.5) * PS_PI / p.height, ph = (3 + 0.5) * 2 * PS_PI / p.width;
                ps_vec3 d = ps_light_ies_direction(&l[k], th, ph);
                double want = ps_ies_candela(ies, th, ph) / ps_ies_flux(ies);
                assert_near(ps_light_profile_lookup(&p, d) * p.peak, want, 0.02 * p.peak);
            }
        }
        ps_light_profile_free(&p);
    }
    ps_scene_destroy(s);
}

/* A spot's table: 1 well inside its cone, 0 well outside; a point's all 1;
 * a quad's cos(theta) about its normal; the 8-bit form rounds. */
static void shapes(void **state)
{
    (void)state;
    ps_scene *s = load("camera eye 0 1 3 target 0 1 0\n"
                       "light spot position 0 1 0 direction 0 -1 0 angle 30 power 1 1 1\n"
                       "light point position 0 1 0 power 1 1 1\n"
                       "light quad corner 0 2 0 edge1 0 0 1 edge2 1 0 0 power 1 1 1\n");
    ps_light_profile p;
    ps_error err;
    assert_int_equal(ps_light_profile_make(s, 0, 32, &p, &err), PS_OK);
    assert_true(ps_light_profile_lookup(&p, ps_v3_norm(ps_v3(0.2, -1, 0))) == 1.0f);
    assert_true(ps_light_profile_lookup(&p, ps_v3_norm(ps_v3(1, -1, 0))) == 0.0f);
    assert_near(p.peak, 1.0 / (2 * PS_PI * (1 - cos(30 * PS_PI / 180))), 1e-9);
    uint8_t *u8 = malloc((size_t)p.width * p.height);
    ps_light_profile_to_u8(&p, u8);
    for (int k = 0; k < p.width * p.height; k++)
        assert_int_equal(u8[k], (int)lround(p.texels[k] * 255.0));
    free(u8);
    ps_light_profile_free(&p);
    assert_int_equal(ps_light_profile_make(s, 1, 16, &p, &err), PS_OK);
    for (int k = 0; k < p.width * p.height; k++)
        assert_true(p.texels[k] == 1.0f);
    ps_light_profile_free(&p);
    assert_int_equal(ps_light_profile_make(s, 2, 64, &p, &err), PS_OK);
    /* edge1 x edge2 = (0 0 1) x (1 0 0) = (0 1 0): up. At 60 degrees from it, cos = 0.5. */
    ps_vec3 d = ps_v3(sin(PS_PI / 3), cos(PS_PI / 3), 0);
    assert_near(ps_light_profile_lookup(&p, d), 0.5, 0.03);
    assert_near(ps_light_profile_lookup(&p, ps_v3(0, -1, 0)), 0.0, 1e-6);
    ps_light_profile_free(&p);
    assert_int_not_equal(ps_light_profile_make(s, 3, 16, &p, &err), PS_OK);
    assert_int_not_equal(ps_light_profile_make(s, 0, 0, &p, &err), PS_OK);
    ps_scene_destroy(s);
}

/* A mesh light (MTL Ke faces): its table holds its flux too. */
static void mesh_light(void **state)
{
    (void)state;
    const char *dir = test_path("");
    char obj[1100], mtl[1100], scn[2300];
    snprintf(obj, sizeof obj, "%slamp.obj", dir);
    snprintf(mtl, sizeof mtl, "%slamp.mtl", dir);
    FILE *f = fopen(mtl, "w");
    fputs("newmtl glow\nKd 0 0 0\nKe 5 5 5\n", f);
    fclose(f);
    f = fopen(obj, "w");
    fputs("mtllib lamp.mtl\nusemtl glow\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", f);
    fclose(f);
    snprintf(scn, sizeof scn, "camera eye 0 1 3 target 0 1 0\nmesh %s\n", obj);
    ps_scene *s = load(scn);
    ps_light_profile p;
    ps_error err;
    assert_int_equal(ps_light_profile_make(s, 0, 64, &p, &err), PS_OK);
    printf("mesh  : the table holds %.5f of the flux\n", held_flux(&p));
    assert_near(held_flux(&p), 1.0, 0.005);
    ps_light_profile_free(&p);
    ps_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_type_holds_its_flux),
        cmocka_unit_test(shapes),
        cmocka_unit_test(mesh_light),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
