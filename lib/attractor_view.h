/* lib/attractor_view.h - a flat region drawn by the system's attractors
 * (cellmap/attractors.h): the cells relabelled, the attractors as the
 * figure's groups and the legend's names. For the command's figures and
 * libcellmap's (cm_result_png); no other part of the command is needed. */
#ifndef CM_LIB_ATTRACTOR_VIEW_H
#define CM_LIB_ATTRACTOR_VIEW_H

#include "cellmap/attractors.h"
#include "cellmap/scm.h"
#include "render/figure.h"

/* A flat region relabelled by attractors, in place: each cell's group id
 * becomes its label's attractor (label[i], cm_attractor_cell_labels), 0
 * where it diverges, and n + 1, a grey group of its own, where it stays
 * outside or is undecided; the attractors' footprint cells in it take
 * their attractor with step 0 (and no other cell has step 0: the markers
 * are the footprints); *groups (freed) becomes the attractors' summaries,
 * as groups, for the figure's colours and legend (*n of them, the grey one
 * last when there is one). */
cm_status attractor_view(const cm_attractor_set *s, cm_region *flat, const int32_t *label,
                         cm_group_info **groups, uint32_t *n, char *msg, size_t msg_size);

/* An attractor's name in legends: "A3 p=1", "A5 aperiodic". */
void attractor_name(const cm_attractor *a, char *out, size_t size);

/* The legend's names of the attractors ("A3 p=1", "A5 aperiodic") that
 * labels[0..used) do not name already, and of the grey group n when the
 * view has one (n > s->n), appended up to cap entries; returns the count. */
int attractor_legend(const cm_attractor_set *s, uint32_t n, cm_group_label *labels, int used,
                     int cap);

#endif
