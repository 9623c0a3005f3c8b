/* cellmap/output.h - where an output file goes, and how it gets there
 * without clobbering what is not its own.
 *
 * Every output is written to a temporary file first; only a complete one
 * reaches its destination:
 *   - a regular file, or a name that does not exist yet: the temporary file
 *     PATH.tmp-PID is renamed over it (a symlink is followed: its target is
 *     replaced, the link stays);
 *   - "-": standard output; a device, FIFO or socket (also through a
 *     symlink, as /dev/stdout is): the destination is opened in place and
 *     the bytes are copied into it; the temporary file is in $TMPDIR (or
 *     /tmp). Such a destination is never replaced, and an output that must
 *     be a regular file (a database) is refused there;
 *   - a directory: refused.
 * Writers write cm_output.tmp however they like (stdio, libpng, SQLite).
 * Failed writes (a full disk, a full device, a closed pipe) are reported
 * with the user's path, their reason and the fix.
 *
 * Killed runs: PATH.tmp-PID is created by cm_output_begin and locked
 * (flock) for as long as it is written. cm_output_begin removes the
 * PATH.tmp-N files of earlier runs (and their SQLite -wal, -shm and
 * -journal files) that are stale: owned by this user, of a process N that
 * no longer runs on this machine, and not locked by any process (a writer
 * on another machine of a network file system keeps its lock). */
#ifndef CM_OUTPUT_H
#define CM_OUTPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "cellmap/status.h"

#define CM_OUTPUT_PATH_MAX 4200

typedef struct cm_output {
    const char *path;              /* as the user gave it */
    char dest[CM_OUTPUT_PATH_MAX]; /* the file renamed over or copied into */
    char tmp[CM_OUTPUT_PATH_MAX];  /* the file the writer writes */
    bool in_place;                 /* copied into dest (stdout, device, FIFO, socket) */
    bool to_stdout;
    bool locked;                   /* lock_fd holds tmp's lock */
    int lock_fd;
} cm_output;

/* Whether path (NULL: none) names standard output: "-", /dev/stdout, /dev/fd/1 or
 * /proc/self/fd/1 (commands then print their reports to stderr). */
bool cm_output_names_stdout(const char *path);

/* Checks path and prepares o: o->tmp is created empty (the writer opens
 * it again, truncating it, or lets SQLite take the empty file), so a
 * missing or read-only directory is found here, before any work.
 * needs_regular: the output must be a regular file (e.g. an SQLite
 * database), so stdout and devices are refused. CM_EINVAL for what the
 * user can fix in the path (the message says how), CM_EIO otherwise. On
 * failure nothing is left to abandon. */
cm_status cm_output_begin(cm_output *o, const char *path, bool needs_regular, char *msg,
                          size_t msg_size);

/* Why `path` (as the user gave it) cannot be written, errno err: the
 * reason and the fix (a missing or read-only directory, a full disk).
 * Returns CM_EINVAL when the path is the problem (missing directory, no
 * permission, read-only file system), CM_EIO otherwise. */
cm_status cm_output_fail(const char *path, int err, char *msg, size_t msg_size);

/* Flushes and closes f, the writer's stream on o->tmp: CM_EIO naming
 * o->path and the reason if a write failed (a full disk, a full device). */
cm_status cm_output_close_stream(const cm_output *o, FILE *f, char *msg, size_t msg_size);

/* Moves the complete temporary file to its destination and removes it. */
cm_status cm_output_commit(cm_output *o, char *msg, size_t msg_size);

/* Removes the temporary file (after a failure; NULL-safe). */
void cm_output_abandon(cm_output *o);

/* For a writer that moves or keeps o->tmp itself (a database being
 * replaced keeps it until it is complete): o forgets the file without
 * removing it; returns the descriptor holding its lock (-1: none), the
 * caller's to close when the file is in place or removed. */
int cm_output_release(cm_output *o);

/* One file a command reads or writes, for cm_files_apart. */
typedef struct cm_file_use {
    const char *path; /* NULL: an unused slot */
    const char *what; /* how the user gave it, for messages: "--png", "the database" */
    bool written;     /* the command writes it (else it only reads it) */
    bool database;    /* an SQLite file: its -wal, -shm and -journal files are its too */
} cm_file_use;

/* Refuses (CM_EINVAL, naming both) an output that is, or resolves to, a
 * file of another entry: the same file by device and inode (symlinks and
 * hard links included), or for names that do not exist yet the same
 * canonical path; a database's -wal, -shm and -journal count as the
 * database. Two outputs may not be one file either. Standard output and
 * devices, FIFOs and sockets are never replaced, so they are not compared
 * (two outputs on stdout are the commands' own rule). Call it before any
 * work: nothing is opened or created. */
cm_status cm_files_apart(const cm_file_use *files, size_t n, char *msg, size_t msg_size);

/* Flushes stdout; CM_EIO with the reason if anything written to it was
 * lost (a full device, a closed pipe). */
cm_status cm_stdout_check(char *msg, size_t msg_size);

/* Opens a file a user gives the command to read (a palette, labels,
 * curves: `what` names it in messages) as text: only a regular file of at
 * most max_bytes, so that a device (/dev/zero), a FIFO or a directory
 * never makes a command hang or read forever. *f is the caller's to close.
 * CM_EIO (not readable) or CM_EINVAL (not a regular file, too large), the
 * message naming the file and the fix. */
cm_status cm_input_open(const char *path, const char *what, uint64_t max_bytes, FILE **f,
                        char *msg, size_t msg_size);

#endif
