/* src/outfile.h - output files of the analysis commands (CSV and chart
 * PNGs), written to a temporary file that reaches PATH only when complete
 * (cellmap/output.h: "-" is stdout, devices and FIFOs are written in place,
 * never replaced), so that a failed run never leaves a half-written file. */
#ifndef CM_SRC_OUTFILE_H
#define CM_SRC_OUTFILE_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/outfile.h"
#include "src/args.h"

/* Checks an output path before the work that fills it (NULL: none): a
 * directory, a missing or read-only directory, or a device where a
 * database must go (needs_regular), is refused at once. Prints "cellmap
 * CMD: ..." and returns EXIT_USAGE then (EXIT_FAIL for a failure of the
 * system, e.g. no file descriptor), else EXIT_OK. */
int outfile_check(const char *cmd, const char *path, bool needs_regular);
/* outfile_check of each of n paths (NULL entries skipped): the first failure. */
int outfiles_check(const char *cmd, const char *const *paths, int n);
/* The same for a chart PNG, which also needs OSMesa: loaded now
 * (render/gl_loader.h), so that a missing library stops the command
 * before its work (EXIT_FAIL). */
int chart_png_check(const char *cmd, const char *path);
/* Both, for the --csv and --png of a command's chart outputs. */
int chart_outputs_writable(const cli *c, const chart_outputs *o);
/* An analysis driver's status: EXIT_OK for CM_OK, else msg said as
 * "cellmap CMD: msg" and EXIT_USAGE for the request's problem (CM_EINVAL)
 * or EXIT_FAIL. */
int analysis_said(const char *cmd, cm_status st, const char *msg);
/* Opens the temporary file; prints "cellmap CMD: ..." and returns false on failure. */
bool outfile_open(const char *cmd, const char *path, outfile *o);
/* Closes and renames it when ok (and every write succeeded), else removes
 * it. Returns whether the file is in place. */
bool outfile_close(const char *cmd, outfile *o, bool ok);

/* Draws the charts one below the other (all of the first one's width) and
 * writes them as a PNG with the given texts (plus Software); prints the
 * problem and returns false on failure. */
bool write_chart_png(const char *cmd, const char *path, const cm_chart *charts, int n_charts,
                     const cm_png_text *texts, int n_texts);

#endif
