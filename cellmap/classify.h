/* cellmap/classify.h - periodic groups, domains and step numbers of a
 * functional graph given by image[] (thesis Algorithm C.8, second half).
 *
 * image[i] is a local index below n, or any value >= n for "no image here"
 * (the sink, or a cell outside the region). On return group[i] is 0 for the
 * sink's domain, else a group id 1..ngroups, numbered in order of the lowest
 * local index of each group's domain; step[i] is 0 for periodic cells, else
 * the number of steps to the periodic group (or to leaving: a cell whose
 * image is >= n has step 1). Linear time; deterministic; needs n < 2^31.
 * Group ids stay below CM_NODE_REF.
 */
#ifndef CM_CLASSIFY_H
#define CM_CLASSIFY_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/status.h"

/* While cells are walked, step[] holds each cell's state: CM_STEP_UNVISITED,
 * CM_STEP_ON_PATH | position for a cell on a walk, or, below
 * CM_STEP_ON_PATH, the final step number (joins flag the cells they resolve
 * again with CM_STEP_ON_PATH too). Group ids stay at most CM_MAX_GROUPS. */
#define CM_STEP_UNVISITED UINT32_C(0xFFFFFFFF)
#define CM_STEP_ON_PATH UINT32_C(0x80000000)
#define CM_MAX_GROUPS UINT32_C(0x7FFFFFFF)
/* group[] of a cell whose sequence leaves the region through recorded exit
 * k (image CM_IMAGE_EXIT_BASE + k of the chain's last cell, its *node*):
 * CM_NODE_REF | k. Such cells are in the sink's domain as far as the region
 * knows; a cluster resolves them through its node table. */
#define CM_NODE_REF UINT32_C(0x80000000)

/* Image values beyond a region's local indices (cellmap/scm.h makes
 * them): the sink (no image, or outside the world), a cell outside the
 * region not recorded, and recorded exit k as CM_IMAGE_EXIT_BASE + k. */
#define CM_IMAGE_SINK UINT32_C(0xFFFFFFFF)
#define CM_IMAGE_EXIT UINT32_C(0xFFFFFFFE)
#define CM_IMAGE_EXIT_BASE UINT32_C(0x80000000)

/* Index into the exit table of an image value, or -1 if it is not a recorded exit. */
static inline int64_t cm_image_exit_index(uint32_t image)
{
    return image >= CM_IMAGE_EXIT_BASE && image < CM_IMAGE_EXIT
               ? (int64_t)(image - CM_IMAGE_EXIT_BASE)
               : -1;
}

static inline int cm_is_node_ref(uint32_t group)
{
    return (group & CM_NODE_REF) && group != UINT32_C(0xFFFFFFFF);
}

/* node_refs: cells whose chains end in a recorded exit get CM_NODE_REF | k
 * instead of group 0 (image values CM_IMAGE_EXIT_BASE + k). */
cm_status cm_classify(uint32_t n, const uint32_t *image, uint32_t *group, uint32_t *step,
                      uint32_t *ngroups, int node_refs, char *msg, size_t msg_size);

/* The same on `threads` threads (one block of cells each; below 2^30 cells),
 * with the same result. */
cm_status cm_classify_threads(uint32_t n, const uint32_t *image, uint32_t *group, uint32_t *step,
                              uint32_t *ngroups, int node_refs, int threads, char *msg,
                              size_t msg_size);

#endif
