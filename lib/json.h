/* lib/json.h - the --json output of every command, in one schema
 * (docs/cellmap.schema.json).
 *
 * A document is one object with "command" first. Shared parts are written
 * by the same functions everywhere: the model and its parameters, the
 * lattice, boxes in state units as [[lo, hi], ...], and groups as
 * {id, kind, period, basin_cells, centre} - the names of the CSV columns
 * and SQL tables. Numbers are the shortest text that reads back exactly;
 * a non-finite number is null. */
#ifndef CM_LIB_JSON_H
#define CM_LIB_JSON_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "cellmap/lattice.h"
#include "cellmap/model.h"
#include "cellmap/scm.h"

enum { JSON_MAX_DEPTH = 16 };

/* A writer: keys and values are separated by commas as they come. */
typedef struct json {
    FILE *f;
    int depth;
    bool has_items[JSON_MAX_DEPTH]; /* an item was written at this depth */
} json;

/* {"command":NAME ...: the document's start. */
void json_begin(json *j, FILE *f, const char *command);
/* ...}\n */
void json_end(json *j);

/* Each takes the member's key inside an object, or NULL inside an array. */
void json_object(json *j, const char *key);
void json_object_end(json *j);
void json_array(json *j, const char *key);
void json_array_end(json *j);
void json_num(json *j, const char *key, double v);
void json_nums(json *j, const char *key, const double *v, int n);
/* A number known to within tol (cm_num_text_near): box edges, centres,
 * durations. */
void json_num_near(json *j, const char *key, double v, double tol);
/* Seconds, to the microsecond. */
void json_seconds(json *j, const char *key, double s);
void json_uint(json *j, const char *key, uint64_t v);
void json_int(json *j, const char *key, int64_t v);
void json_str(json *j, const char *key, const char *s);
void json_bool(json *j, const char *key, bool v);
/* Text that is JSON already (a parameters object). */
void json_raw(json *j, const char *key, const char *text);

/* s as a JSON string, quoted and escaped. */
void json_str_text(FILE *f, const char *s);

/* "model":NAME,"params":{...},"state":[names]: the model as the
 * command used it. */
void json_model(json *j, const cm_model *m);
/* "lattice":{"origin":[...],"width":[...]} */
void json_lattice(json *j, const cm_lattice *lat);
/* key: [[lo, hi], ...], the box's cells' extent in state units. */
void json_box(json *j, const char *key, const cm_lattice *lat, const cm_box *box);
/* A group's id, kind, period, basin_cells and centre (to the lattice's
 * resolution), inside an object the caller opened (and may add to). */
void json_group_fields(json *j, const cm_group_info *g, const cm_lattice *lat);
/* "groups":[{id, kind, period, basin_cells, centre}, ...] */
void json_groups(json *j, const cm_group_info *g, uint32_t n, const cm_lattice *lat);


#endif
