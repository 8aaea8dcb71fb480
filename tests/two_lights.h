/* two_lights.h: the default scene's box and spheres with a point light (0)
 * and a spot (1) whose power the test chooses, for the repair and
 * per-stratum stream tests (test_repair, test_tracer_strata). */
#ifndef PS_TESTS_TWO_LIGHTS_H
#define PS_TESTS_TWO_LIGHTS_H

/* Everything but the spot's power, which follows as "R G B\n". */
#define TWO_LIGHTS_SCENE                                                  \
    "camera eye 0 1 3.4 target 0 1 0 up 0 1 0 fov 40\n"                  \
    "material white diffuse albedo 0.75 0.75 0.75\n"                     \
    "material red diffuse albedo 0.75 0.25 0.25\n"                       \
    "material glass dielectric ior 1.5\n"                                \
    "material mirror mirror reflectance 1 1 1\n"                         \
    "quad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0 material white\n"       \
    "quad corner -1 2 -1 edge1 2 0 0 edge2 0 0 2 material white\n"       \
    "quad corner -1 0 -1 edge1 2 0 0 edge2 0 2 0 material white\n"       \
    "quad corner -1 0 -1 edge1 0 2 0 edge2 0 0 2 material red\n"         \
    "quad corner 1 0 -1 edge1 0 0 2 edge2 0 2 0 material white\n"        \
    "sphere center 0.35 0.4 0.2 radius 0.4 material glass\n"             \
    "sphere center -0.45 0.35 -0.4 radius 0.35 material mirror\n"        \
    "light point position 0 1.9 0 power 100 100 100\n"                   \
    "light spot position 0.5 1.9 0.3 direction 0 -1 0 angle 40 power "

#endif
