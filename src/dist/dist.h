/* dist.h: photosplat-ref on MPI (photosplat-ref-mpi). The only code that
 * calls MPI; built only into that program (mk/mpi.mk), never into the
 * library, so a build without MPI works unchanged.
 *
 * How the work splits (the hooks of app/ref_dist.h and render.h's
 * ps_render_share; docs/reference-renderer.md has the measurements):
 * - photons: rank r traces the r-th of N equal index ranges of each map;
 *   photon i depends only on (scene, seed, i), and the ranges joined in rank
 *   order are the single process's map, byte for byte, so every rank then
 *   balances the same kd-tree;
 * - the irradiance cache: each chunk of positions is split by position
 *   (interleaved: position i of the chunk to rank i mod N), the records
 *   exchanged, and every rank adds all of them in slot order, the order one
 *   process adds them in: every rank holds the single process's cache;
 * - tiles: rank 0 hands them out one at a time (a server thread answers
 *   requests; each other rank keeps one request in flight per worker thread
 *   so that it never waits for the answer) and collects the finished tile
 *   buffers, which it joins in tile order as one process does;
 * - outputs: rank 0 alone writes, through ps_outfile, once every rank has
 *   agreed that the run succeeded.
 * Every rank's stdout goes to /dev/null except rank 0's, and its stderr to a
 * temporary file: a rank that fails alone has its last line printed by rank
 * 0 ("rank N: ..."); a failure every rank shares (a bad scene) is printed
 * once, by rank 0. */
#ifndef PS_DIST_DIST_H
#define PS_DIST_DIST_H

#include "app/ref_dist.h"

/* The program run on every rank: photosplat-ref's main with the hooks. */
typedef int (*ps_dist_program)(int argc, char **argv, const ps_ref_dist *dist);

/* Starts MPI (thread level SERIALIZED), runs `program` on every rank with
 * the hooks, agrees on the exit status, ends MPI; the exit status. */
int ps_dist_main(int argc, char **argv, ps_dist_program program);

#endif
