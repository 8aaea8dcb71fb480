/* gl_specular.h: the `specular` layer in fixed-function GL (issue 15):
 * environment cube maps rendered from each mirror or glass object's centre
 * with the preview itself, and the objects drawn with the per-vertex
 * lookups and Fresnel weights that preview/specular.h traces on the CPU.
 *
 * A cube map is six faces of PS_GL_SPECULAR_CUBE_SIZE^2 RGBA16F texels,
 * rendered as the view is (the depth prepass, the direct layer with its
 * shadow maps, the area lights, then the caustic and global splats of the
 * photons so far, at most PS_GL_SPECULAR_ENV_CAUSTIC and _GLOBAL, a prefix with
 * the level of detail's grown radius), every mirror and glass object left
 * out (the lookups trace through them on the CPU), at exposure 1: radiance.
 * Faces are refreshed round-robin while photons arrive: in snap the first
 * round after a change over PS_GL_SPECULAR_FIRST_REFRESHES refreshes from
 * the first after the new view, then (the window: always) as
 * PS_GL_SPECULAR_TIME_SHARE of tau allows
 * (a face every few refreshes; never in a new view's refresh: the first
 * picture, the first after an edit and a moving camera's come as fast as
 * without the layer), the last round once they all arrived
 * over a few refreshes whatever the budget, all at once for a single frame and a snapshot's last
 * picture (with a deadline, snap's checkpoints: only the faces that end
 * before it). Faces are rendered into a second map of the cube, shown once
 * its six faces are from one centre and one state of the scene (then the
 * objects are redrawn); until then the last whole map shows, its lookups
 * looking from where it was rendered (ps_session_set_specular_centre), so
 * that an object moved shows at once what its old map saw of the points its
 * new eye paths reach. They are kept
 * while only the camera moves; a new layer set, an edit or new GL lights
 * start a new round. Once the camera holds still and its per-pixel paths
 * are traced (preview/specular.h), each path is drawn as a one-pixel point
 * looking its cube up, times its weight, added; before that (a moving
 * camera, or paths still being traced) the objects are drawn
 * PS_SPECULAR_TERMS times, each pass one lookup direction (texture
 * coordinates into the object's cube) modulated by its weight (vertex
 * colours), added together. Glossy objects always take the per-vertex
 * passes, looking up their cube's blurred level (gl_specular_blur.h). */
#ifndef PS_GL_GL_SPECULAR_H
#define PS_GL_GL_SPECULAR_H

#include "gl/gl_render.h"
#include "preview/specular.h"

#define PS_GL_SPECULAR_CUBE_SIZE 128
#define PS_GL_SPECULAR_FACES_PER_REFRESH 1
/* Past the first round, faces take at most this share of tau on average. */
#define PS_GL_SPECULAR_TIME_SHARE 0.15
/* Photons a cube face splats from each map. The caustic's are small and
 * cheap to fill, and fewer grow their radius toward the global one (8 192
 * blurred the ring's caustic into its shadow); the global splats' fill is
 * most of what a face costs. */
#define PS_GL_SPECULAR_ENV_CAUSTIC 65536
#define PS_GL_SPECULAR_ENV_GLOBAL 16384
/* A face's time grows as its fill to this power (ps_gl_specular_face_foreseen):
 * fitted to the default box's faces, 0.03 s at 3.2*10^5 pixels foreseeing
 * 0.16 s at 5.1*10^6 (0.18 measured). */
#define PS_GL_SPECULAR_FILL_GROWTH 0.6
/* Once every photon has arrived, the last round is drawn over this many
 * refreshes, budget or not. */
#define PS_GL_SPECULAR_SETTLE_REFRESHES 4
/* With ps_gl_specular_set_first_round (photosplat-snap --time, whose
 * checkpoints are what photosplat-bench measures): the first round after a
 * change (the first picture, an edit, new layers or lights) is drawn over
 * this many refreshes, budget or not, from the first refresh after the new
 * view's. The window keeps the budget (its frame rate; 3 faces a refresh
 * made the sanitizer build's window miss its scripted frames). */
#define PS_GL_SPECULAR_FIRST_REFRESHES 4
/* That first round draws shadows only up to this many GL lights (an area
 * light's virtual lights make faces dear): the later rounds draw them all. */
#define PS_GL_SPECULAR_QUICK_SHADOW_LIGHTS 4

typedef struct ps_gl_specular ps_gl_specular;

/* cube_size 0: PS_GL_SPECULAR_CUBE_SIZE. Needs a current context. */
ps_status ps_gl_specular_create(int cube_size, ps_gl_specular **out, ps_error *err);
void ps_gl_specular_destroy(ps_gl_specular *g); /* accepts NULL */

/* The first round of faces after a change over `refreshes` refreshes
 * whatever the budget (0, the default: within the budget, as later rounds). */
void ps_gl_specular_set_first_round(ps_gl_specular *g, int refreshes);
/* Whether that first round's faces, too, end by the deadline
 * (ps_gl_specular_set_deadline) in a refresh: for a program that gives them
 * its waits instead (ps_gl_specular_idle). */
void ps_gl_specular_hold_first_round(ps_gl_specular *g, bool held);
/* A face never timed yet, where a deadline foresees it (ps_gl_specular_idle's
 * waits, a held first round's refreshes), taken to last `seconds`; 0, the
 * default: it may start until the deadline. (Allowed so, the first face of
 * the 0.1 s checkpoint's frame, 0.01-0.025 s with llvmpipe's first variants
 * of the face pass, made that frame late where it fitted without.) */
void ps_gl_specular_set_face_guess(ps_gl_specular *g, double seconds);

/* The next refreshes' cube faces past the first round after a change end
 * by `at` (ps_now_seconds' clock; 0: no limit), as each face's last time
 * predicts: a face that would pass it waits for a later refresh
 * (photosplat-snap: the refreshes before a checkpoint leave it on time,
 * pace.h). Not for `faces` 0 (all at once). Each face is then finished and
 * timed on its own. The first round's faces, unless held
 * (ps_gl_specular_hold_first_round), are not foreseen against it but still
 * start only before it. */
void ps_gl_specular_set_deadline(ps_gl_specular *g, double at);
/* The eye paths a refresh left owed while every cube was black (the
 * session's specular_wait: the mirrors' lookups and per-pixel paths, all
 * traced in the refresh that first shows a cube) are traced only until
 * `at` (ps_now_seconds' clock; 0, the default: all of them); the layer
 * stays black in a picture while some are still owed, and the next
 * refreshes and waits (ps_gl_specular_idle) trace on from where it stopped.
 * photosplat-snap's checkpoint frames: the ring's 0.04 s of them landed
 * its 8-bit 0.2 s checkpoint at 0.25 s. */
void ps_gl_specular_set_paths_deadline(ps_gl_specular *g, double at);
/* Whether a face predicted to take `estimate` seconds (0: not timed yet,
 * allowed until the deadline) may start at `now` under deadline `at` (0:
 * none). */
bool ps_gl_specular_face_fits(double now, double at, double estimate);
/* A face that took `seconds` when its splats covered fill_then pixels
 * (ps_session_env_fill), foreseen when they cover fill_now: longer by
 * (fill_now / fill_then)^PS_GL_SPECULAR_FILL_GROWTH when they cover more,
 * never shorter (a face's fixed part: its mesh, its shadow passes). The
 * default box's faces, drawn at 256^2 with the bench's caps: 0.02-0.05 s at
 * 0.2-1.3*10^6 pixels, 0.11-0.12 s at 2.8-5.0*10^6, 0.18 s at 5.1*10^6 and
 * 0.31 s at 1.8*10^7 (llvmpipe's fill grows slower than the pixels counted:
 * overlapping splats, hidden ones). A face never drawn was foreseen from
 * the others alone: that 0.18 s face at 0.03 s, and a refresh planned to
 * end before the 0.5 s checkpoint's frame drew it and showed that
 * checkpoint at 0.62-0.64 s. A face never timed is foreseen from the timed
 * face nearest it in fill, scaled by the same power either way. */
double ps_gl_specular_face_foreseen(double seconds, double fill_then, double fill_now);

/* The seconds the next refresh's faces (a few a refresh, not a new view's)
 * take that the deadline does not foresee (each still starts only before
 * it): the first round's (ps_gl_specular_set_first_round)
 * while it lasts and is not held (ps_gl_specular_hold_first_round), each face
 * at its own last time scaled up by its fill since
 * (ps_gl_specular_face_foreseen), a face never timed from the timed one
 * nearest it in fill, scaled by their fills either way; HUGE_VAL before any
 * was drawn (not known: a caller that must end by a time holds them). */
double ps_gl_specular_unheld_seconds(ps_gl_specular *g, ps_session *s);

/* The seconds every face of every cube takes (a snapshot's last picture,
 * `faces` 0), each at its own last time, else as the last refresh's faces
 * took (not the dearest seen: the mirror box's one face's first full render
 * took 0.2 s where the others took 0.03); 0 without cubes or before any
 * face was timed (not known). */
double ps_gl_specular_all_seconds(const ps_gl_specular *g);

/* While the program waits anyway (photosplat-snap before the frame a
 * checkpoint shows, app/pace.h), after refresh f: faces, the first round's
 * too, each while it is predicted to end by `deadline` (before any face was
 * timed, at the guess: ps_gl_specular_set_face_guess). Nothing else of the
 * frame is drawn. */
ps_status ps_gl_specular_idle(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, const ps_session_frame *f,
                              double deadline, ps_error *err);

/* Before drawing refresh f of session s: up to `faces` cube faces rendered
 * (0: every face of every cube), when f shows the specular layer. Leaves the
 * renderer's view, the viewport and the framebuffer binding as they were. */
ps_status ps_gl_specular_refresh(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, const ps_session_frame *f,
                                 int faces, ps_error *err);
/* The specular objects' lookups times exposure added into the bound
 * framebuffer over the renderer's current view (its depth already there):
 * the per-pixel points when traced for the session's camera, else the
 * per-vertex lookups. */
void ps_gl_specular_draw(ps_gl_specular *g, ps_gl_renderer *r, ps_session *s, double exposure);
/* The layered path (the window, snap --time in float): the specular layer
 * as a texture of l's size sharing l's depth, redrawn when the cubes, the
 * lookups or the view changed (while the camera moves, with the heaviest
 * lookup only: one pass instead of PS_SPECULAR_TERMS), and added to l's
 * composite times f's direct gain (0 when f does not show it). */
ps_status ps_gl_specular_layer(ps_gl_specular *g, ps_gl_layers *l, ps_gl_renderer *r, ps_session *s,
                               const ps_session_frame *f, ps_error *err);
/* The layer's weight in l's composite: the gain, or 0 to leave it out (a
 * layer read alone). */
void ps_gl_specular_set_gain(ps_gl_specular *g, ps_gl_layers *l, double gain);

/* Whether the cube maps show every photon, the still camera's per-pixel
 * paths are traced and the objects were redrawn from them (or the layer is
 * not shown): nothing left to refresh. A script's `wait done` waits for it
 * too. */
bool ps_gl_specular_done(const ps_gl_specular *g, ps_session *s);

/* Whether every cube has been shown since the last change, so that no
 * mirror or glass is black for want of its first map (true without cubes,
 * or with the layer off). New virtual lights discard the faces of a map
 * still being rendered: photosplat-snap refines an area light only then. */
bool ps_gl_specular_all_shown(const ps_gl_specular *g, ps_session *s);

/* For tests: every face of every cube filled with radiance `value` (a
 * furnace), marked fresh so that refreshes keep it. */
void ps_gl_specular_fill(ps_gl_specular *g, ps_session *s, float value);

/* What ran: cube faces rendered so far. */
unsigned ps_gl_specular_faces_rendered(const ps_gl_specular *g);
/* Cube maps of their own held now, shown and back (a cube never shown
 * shows one black map that all share, and has a back map only once a face
 * was rendered into it). */
int ps_gl_specular_maps(const ps_gl_specular *g);
/* The next refresh draws every face of every cube again, from the photons
 * there, whatever earlier refreshes and waits drew: a last picture whose
 * cube maps depend on the photons alone (photosplat-snap's). A face drawn
 * in a wait after the feed ended was kept by the last picture, and did not
 * match one a refresh draws (the default box's specular layer at 48^2
 * differed from a whole frame's by relMSE 4*10^-8 in some runs, the
 * cause not found). */
void ps_gl_specular_redraw_all(ps_gl_specular *g);

#endif
