/* tool_material_mask.c: a mask for photosplat-compare --mask, for the CLI
 * tests: tool_material_mask SCENE WxH MATERIAL OUT.pfm writes 1 where the
 * eye ray through a pixel's centre, and those of its 8 neighbours, first
 * meet a surface of MATERIAL (its edges left out), else 0. Prints the
 * pixels set. Exit status 2 on bad input. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "photon/world.h"
#include "scene/camera.h"
#include "scene/scene.h"

static bool sees(const ps_world *w, const ps_camera_frame *cam, int x, int y, uint32_t material)
{
    ps_surface sp;
    if (x < 0 || y < 0 || x >= cam->width || y >= cam->height)
        return false;
    return ps_world_intersect(w, ps_camera_ray(cam, x + 0.5, y + 0.5), INFINITY, &sp) && sp.material == material;
}

int main(int argc, char **argv)
{
    int width, height;
    if (argc != 5 || sscanf(argv[2], "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0) {
        fprintf(stderr, "usage: tool_material_mask SCENE WxH MATERIAL OUT.pfm\n");
        return 2;
    }
    ps_error err;
    ps_scene *s;
    ps_world *w = NULL;
    if (ps_scene_load(argv[1], NULL, &s, &err) != PS_OK || ps_world_create(s, NULL, &w, &err) != PS_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    size_t nm;
    const ps_material *mats = ps_scene_materials(s, &nm);
    uint32_t material = UINT32_MAX;
    for (size_t i = 0; i < nm; i++)
        if (!strcmp(mats[i].name, argv[3]))
            material = (uint32_t)i;
    if (material == UINT32_MAX) {
        fprintf(stderr, "%s: no material '%s'\n", argv[1], argv[3]);
        return 2;
    }
    ps_camera_frame cam = ps_camera_frame_make(ps_scene_camera(s), width, height);
    float *v = calloc((size_t)width * height, sizeof *v);
    size_t set = 0;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            bool all = true;
            for (int dy = -1; dy <= 1 && all; dy++)
                for (int dx = -1; dx <= 1 && all; dx++)
                    all = sees(w, &cam, x + dx, y + dy, material);
            v[(size_t)y * width + x] = all ? 1.0f : 0.0f;
            set += all;
        }
    ps_status st = ps_pfm_write_gray(v, width, height, argv[4], &err);
    if (st != PS_OK)
        fprintf(stderr, "%s\n", err.msg);
    else
        printf("pixels=%zu\n", set);
    free(v);
    ps_world_destroy(w);
    ps_scene_destroy(s);
    return st == PS_OK ? 0 : 2;
}
