/* lib/stats_report.h - what an explore session's `stats` prints of its
 * view (lib/session.h: session_count): the cells, the groups and the
 * attractors with the most cells in view, the cluster's memory and disk,
 * as text and as one JSON document (docs/cellmap.schema.json). */
#ifndef CM_LIB_STATS_REPORT_H
#define CM_LIB_STATS_REPORT_H

#include <stdio.h>

#include "lib/session.h"

/* At most 20 groups and attractors, the most cells in view first. */
void stats_report(FILE *f, const session *s, const session_stats *v);
/* Every group and attractor in view, in id order. */
void stats_json(FILE *f, const session *s, const session_stats *v);

#endif
