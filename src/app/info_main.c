/* info_main.c: photosplat-info: load a scene and describe what it holds.
 * What `make run` shows on a machine where no preview program is built yet;
 * also the quickest way to check a scene file. */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "app/cli.h"
#include "scene/ies.h"
#include "scene/scene.h"
#include "scene/texture.h"

static const char usage[] =
    "usage: photosplat-info SCENE.scn|MODEL.obj [--scene]\n"
    "\n"
    "Loads a scene (and the OBJ/MTL files it names) and prints its camera, image\n"
    "size, materials, objects, lights and photon defaults. Exit status 0 when the\n"
    "scene is valid; a malformed scene prints one line 'file:line: problem' on\n"
    "stderr and exits with status 2. A MODEL.obj stands for the scene made from\n"
    "it: camera framing it, its MTL materials and emitters, a default light when\n"
    "it has none.\n"
    "\n"
    "options:\n"
    "  --scene  print the scene as a .scn file instead (paths relative to the\n"
    "           current directory), ready to save and edit\n"
    "  --help   this text\n";

static void print_vec(const char *label, ps_vec3 v) { printf("%s (%g, %g, %g)", label, v.x, v.y, v.z); }

static void describe(const ps_scene *s)
{
    const ps_camera *c = ps_scene_camera(s);
    const ps_scene_defaults *d = ps_scene_get_defaults(s);
    size_t nmat, ntri, nobj, nlight, npos;
    const ps_material *mats = ps_scene_materials(s, &nmat);
    const ps_object *objs = ps_scene_objects(s, &nobj);
    const ps_light *lights = ps_scene_lights(s, &nlight);
    (void)ps_scene_triangles(s, &ntri);
    (void)ps_scene_positions(s, &npos);

    printf("scene      %s\n", ps_scene_path(s));
    printf("camera    ");
    print_vec(" eye", c->eye);
    print_vec(" target", c->target);
    print_vec(" up", c->up);
    printf(" fov %g deg\n", c->fov_deg);
    printf("image      %dx%d\n", d->width, d->height);
    ps_aabb b = ps_scene_bounds(s);
    printf("bounds    ");
    print_vec("", b.lo);
    print_vec(" ..", b.hi);
    printf("\n");

    printf("materials  %zu\n", nmat);
    for (size_t i = 0; i < nmat; i++) {
        const ps_material *m = &mats[i];
        printf("  %-24s %-10s", m->name, ps_material_type_name(m->type));
        switch (m->type) {
        case PS_MAT_DIFFUSE: printf(" albedo %g %g %g", m->albedo.r, m->albedo.g, m->albedo.b); break;
        case PS_MAT_GLOSSY:
            printf(" albedo %g %g %g specular %g %g %g exponent %g", m->albedo.r, m->albedo.g, m->albedo.b,
                   m->specular.r, m->specular.g, m->specular.b, m->exponent);
            break;
        case PS_MAT_MIRROR: printf(" reflectance %g %g %g", m->reflectance.r, m->reflectance.g, m->reflectance.b); break;
        case PS_MAT_DIELECTRIC: printf(" ior %g", m->ior); break;
        }
        if (!ps_rgb_is_black(m->emission))
            printf(" emission %g %g %g", m->emission.r, m->emission.g, m->emission.b);
        if (m->texture) {
            const ps_texture *t = ps_scene_texture(s, m->texture - 1);
            printf(" texture %s %dx%d", ps_texture_path(t), ps_texture_width(t), ps_texture_height(t));
        }
        printf("\n");
    }

    size_t count[3] = {0, 0, 0}, specular = 0;
    for (size_t i = 0; i < nobj; i++) {
        count[objs[i].type]++;
        specular += objs[i].specular != 0;
    }
    printf("objects    %zu (%zu meshes, %zu quads, %zu spheres), %zu triangles, %zu vertices; %zu specular\n", nobj,
           count[PS_OBJ_MESH], count[PS_OBJ_QUAD], count[PS_OBJ_SPHERE], ntri, npos, specular);

    ps_rgb total = ps_scene_total_power(s);
    printf("lights     %zu, total power %g %g %g W, %g lm\n", nlight, total.r, total.g, total.b,
           ps_scene_total_lumens(s));
    for (size_t i = 0; i < nlight; i++) {
        const ps_light *l = &lights[i];
        printf("  %-6s", ps_light_type_name(l->type));
        print_vec(" at", l->position);
        printf(" power %g %g %g W", l->power.r, l->power.g, l->power.b);
        if (l->type == PS_LIGHT_SPOT)
            printf(" half-angle %g deg", l->angle_deg);
        if (l->area > 0.0)
            printf(" area %g m2", l->area);
        if (l->type == PS_LIGHT_IES) {
            const ps_ies *ies = ps_scene_ies_profile(s, l->profile);
            const ps_ies_info *in = ps_ies_get_info(ies);
            printf(" %s (%s, %d x %d angles, %g lm in the table, peak %g cd)", ps_ies_name(ies), in->format,
                   in->vertical_count, in->horizontal_count, ps_ies_flux(ies), ps_ies_peak(ies));
        }
        printf(" (line %d)\n", l->line);
    }
    printf("photons    caustic %lld, global %lld\n", (long long)d->caustic_photons, (long long)d->global_photons);
    printf("radius     caustic %g, global %g\n", d->caustic_radius, d->global_radius);
    printf("passes     caustic: %s\n", specular ? "needed (specular objects present)"
                                                  : "skipped (no mirror or dielectric object)");
}

int main(int argc, char **argv)
{
    ps_cli cli = ps_cli_begin("photosplat-info", argc, argv);
    ps_error err;
    ps_error_clear(&err);
    const char *scene_path = NULL;
    bool print_scene = false;
    while (ps_cli_next(&cli)) {
        if (ps_cli_is(&cli, "--help") || ps_cli_is(&cli, "-h")) {
            fputs(usage, stdout);
            return PS_EXIT_OK;
        } else if (ps_cli_is(&cli, "--scene")) {
            print_scene = true;
        } else if (ps_cli_positional(&cli)) {
            if (scene_path) {
                ps_error_set(&err, PS_ERR_PARSE, "photosplat-info: more than one scene given ('%s')", ps_cli_arg(&cli));
                return ps_cli_fail(&err);
            }
            scene_path = ps_cli_arg(&cli);
        } else {
            ps_cli_unknown(&cli, &err);
            return ps_cli_fail(&err);
        }
    }
    if (!scene_path) {
        ps_error_set(&err, PS_ERR_PARSE, "photosplat-info: no scene given (see --help)");
        return ps_cli_fail(&err);
    }
    ps_scene *scene;
    if (ps_scene_load(scene_path, NULL, &scene, &err) != PS_OK)
        return ps_cli_fail(&err);
    ps_status st = print_scene ? ps_scene_print(scene, stdout, &err) : PS_OK;
    if (!print_scene)
        describe(scene);
    ps_scene_destroy(scene);
    if (st != PS_OK)
        return ps_cli_fail(&err);
    return PS_EXIT_OK;
}
