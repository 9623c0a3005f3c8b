/* lib/ranks.h - a solve shared by several processes: MPI ranks, started by
 * mpirun on one host or many.
 *
 * Rank 0 runs the solve as one process would. Its clusters' boxes go to
 * the workers (the other ranks) as the solve claims them, in its order:
 * a worker is given a box whenever it holds fewer than WORKER_QUEUE (2:
 * the one it solves and the next), the one holding fewest first, and rank
 * 0 solves a box itself only when every worker holds that many. Rank 0
 * joins every region, which on one process takes a thread from the
 * solving; so it solves what it can between joins, and a region costly
 * to solve goes to whichever rank is free: the balance follows the
 * measured cost of each box, not a rule fixed in advance. Which rank
 * solved a box therefore depends on timing; nothing written does. A
 * worker solves its boxes in order with all its threads and sends each
 * region back: its cells (image, group, step: 12 bytes a cell), its
 * exits and the sizes of its nodes' trees (so that rank 0 makes the node
 * table without reading the cells). Rank 0 joins them in the order one process would, so the
 * cluster, its database, figures and exports are byte for byte those of
 * a solve without MPI, whatever R and each rank's thread count.
 *
 * The protocol, in order:
 *   1. ranks_open (every rank, before the command): the ranks run the same
 *      binary (a hash of its file) with the same command line, or rank 0
 *      says which does not and every rank fails;
 *   2. ranks->ready (every rank, once: where the solve starts, or after a
 *      command that failed before it): whether every rank got there, so
 *      that a rank that failed early (a plugin missing on its host) stops
 *      the others instead of leaving them waiting;
 *   3. workers: ranks->serve until rank 0 says stop; rank 0: the cluster's
 *      region source (cellmap/join.h), then ranks->stop with its status,
 *      which drains what workers still send.
 * A rank killed mid-solve makes mpirun end the job; the database keeps
 * every join committed, and a resumed solve completes it with any R.
 *
 * Implemented by lib/ranks.c, linked into cellmap-mpi (the program
 * `cellmap` runs under mpirun) and into libcellmap-mpi.so (which
 * libcellmap opens under mpirun), so that nothing else loads MPI. */
#ifndef CM_LIB_RANKS_H
#define CM_LIB_RANKS_H

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

#include "cellmap/join.h"

/* The ranks mpirun started, from the environment it gives each process
 * (Open MPI, or a PMI launcher such as MPICH's): 0 if it did not start this
 * one. Read without MPI: the command decides whether to run cellmap-mpi. */
static inline int ranks_launch_env(const char *open_mpi, const char *pmi)
{
    const char *n = getenv(open_mpi);
    n = n ? n : getenv(pmi);
    return n ? atoi(n) : 0;
}

static inline int ranks_launched(void)
{
    return ranks_launch_env("OMPI_COMM_WORLD_SIZE", "PMI_SIZE");
}

static inline int ranks_launched_rank(void)
{
    return ranks_launch_env("OMPI_COMM_WORLD_RANK", "PMI_RANK");
}

typedef struct solve_ranks solve_ranks;

struct solve_ranks {
    int rank, size;
    /* Step 2: ok says whether this rank got to the solve, and `what` (a
     * text) what it is to solve: ranks asked for different solves would
     * make a wrong cluster. *all_ok: whether every rank got there with
     * rank 0's text; *first_failed: the lowest rank that did not;
     * *differs: that it got there with another text. */
    void (*ready)(solve_ranks *rk, bool ok, const char *what, bool *all_ok, int *first_failed,
                  bool *differs);
    /* Step 3, a worker: solves the boxes rank 0 sends, on the lattice with
     * max_steps and `threads` threads (0: the OpenMP default), until rank 0
     * stops it; returns rank 0's status then (CM_OK: the solve succeeded). */
    cm_status (*serve)(solve_ranks *rk, const cm_model *model, const cm_lattice *lat,
                       int max_steps, int threads, char *msg, size_t msg_size);
    /* Step 3, rank 0: the workers stop, told the solve's status, which is
     * returned. */
    cm_status (*stop)(solve_ranks *rk, cm_status status);
    cm_region_source source; /* rank 0's regions solved by workers */
    bool readied;            /* step 2 done */
    uint64_t bytes_received; /* by rank 0 from workers, requests and replies */
    uint64_t bytes_sent;     /* by rank 0 to workers */
    uint64_t regions_received;
    uint64_t *regions_by_rank; /* rank 0's: the boxes each rank was given to solve */
};

/* Starts MPI (every rank, first thing; argc and argv may be NULL, and MPI
 * may have been started by the program, which then ends it) and does step
 * 1: every rank runs the same `program` (a path; NULL: this process's
 * executable) with the same arguments (argv, when given): *out is this
 * rank's (ranks_close frees it). On failure msg says why (rank 0 names the
 * rank that differs); every rank then fails. */
cm_status ranks_open(int *argc, char ***argv, const char *program, solve_ranks **out, char *msg,
                     size_t msg_size);

/* Step 2 for a command that ended before its solve did (if it did not
 * already), then MPI's end (unless the program started MPI). */
void ranks_close(solve_ranks *rk, bool ok);

/* The same two, exported by libcellmap-mpi.so for libcellmap, which opens
 * it under mpirun (cm_ranks_open, cellmap/cellmap.h): program is the file
 * of libcellmap. */
typedef cm_status (*ranks_open_fn)(const char *program, solve_ranks **out, char *msg,
                                   size_t msg_size);
typedef void (*ranks_close_fn)(solve_ranks *rk, bool ok);
#define RANKS_OPEN_SYMBOL "cm_mpi_ranks_open"
#define RANKS_CLOSE_SYMBOL "cm_mpi_ranks_close"

#endif
