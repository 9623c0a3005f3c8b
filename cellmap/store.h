/* cellmap/store.h - the .cmdb cluster database (SQLite).
 *
 * A .cmdb file holds one cluster: metadata (model, parameters as JSON,
 * lattice, tool version, command line), regions, the regions' cell arrays as
 * little-endian BLOB pages of CM_STORE_PAGE_CELLS cells, and the periodic
 * groups. The file carries application_id CM_STORE_APP_ID and user_version
 * CM_STORE_VERSION; files with another application id or a newer version are
 * refused and never modified. The byte layout is documented in FORMAT.md.
 *
 * cm_store_save writes a complete database to PATH.tmp-PID in one
 * transaction and renames it over PATH, so PATH is either the old file or
 * the complete new one. An existing PATH that is not a cellmap database is
 * refused (CM_EFORMAT) and left untouched.
 */
#ifndef CM_STORE_H
#define CM_STORE_H

#include "cellmap/model.h"
#include "cellmap/scm.h"

#define CM_STORE_APP_ID 0x434D4442 /* "CMDB" */
#define CM_STORE_VERSION 1
#define CM_STORE_PAGE_CELLS 65536

typedef struct cm_store_meta {
    const cm_model *model;    /* name and parameter values */
    const cm_lattice *lattice;
    const char *command;      /* command line that made the file, may be NULL */
    const char *tool_version;
    long long created;        /* seconds since the epoch (SOURCE_DATE_EPOCH or 0) */
} cm_store_meta;

cm_status cm_store_save(const char *path, const cm_store_meta *meta, const cm_region *r,
                        const cm_group_info *groups, char *msg, size_t msg_size);

/* Checks that path is a cellmap database this version can read. */
cm_status cm_store_check(const char *path, char *msg, size_t msg_size);

/* Reads the lattice and the (single) region's arrays of a saved file into a
 * newly allocated region. model_name receives the model's name. */
cm_status cm_store_load(const char *path, cm_lattice *lat, cm_region *r, char *model_name,
                        size_t name_size, char *msg, size_t msg_size);

/* Parameters as a JSON object text, e.g. {"alpha":0.078,"mode":"output"}. */
void cm_params_json(const cm_params *p, char *buf, size_t size);

#endif
