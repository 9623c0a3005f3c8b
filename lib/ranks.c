#include "lib/ranks.h"

#include <fcntl.h>
#include <mpi.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cellmap/grow.h"
#include "cellmap/scm.h"

enum { TAG_BOXES = 1, TAG_STOP, TAG_DONE, TAG_REGION /* and above: a region, by its index */ };

/* Arrays go in pieces of at most this many bytes: MPI counts in int. */
#define PIECE (UINT64_C(1) << 30)

/* A box a worker is asked to solve: its place in the solve's order. */
typedef struct box_request {
    uint64_t index;
    cm_box box;
} box_request;

/* What a worker sends first for a box: the region's sizes, or why it
 * could not solve it; then (solved) its image, group and step arrays, its
 * exits and its trees' sizes (cm_region_trees, so that rank 0 makes the
 * node table without a pass over the cells), as separate messages. */
typedef struct region_header {
    uint64_t index, ncells, nexits;
    int32_t status, exits_recorded;
    uint32_t ngroups;
    cm_box box;
    char msg[256];
} region_header;

/* A box request on its way to a worker, kept until the send is done. */
typedef struct pending_send {
    box_request q;
    MPI_Request req;
} pending_send;

/* Boxes a worker is given beyond the one it solves: it goes on to the
 * next without waiting for rank 0, which may be joining. */
#define WORKER_QUEUE 2

typedef struct mpi_ranks {
    solve_ranks pub;
    pthread_mutex_t lock; /* rank 0's threads use MPI one at a time */
    uint64_t asked;       /* boxes asked for by the calls before */
    uint64_t first;       /* index of the current call's first box */
    const cm_box *boxes;  /* the current call's */
    uint32_t nboxes;
    uint32_t claimed;     /* boxes of the call claimed so far */
    int *holder;          /* per box of the call: the worker solving it, 0: rank 0 */
    int *held;            /* per worker: boxes given whose regions have not arrived */
    uint64_t *given;      /* per worker: WORKER_QUEUE places, the first held in order */
    int tag_span;         /* region tags: TAG_REGION + index mod tag_span */
    pending_send **sends; /* box requests not known to be sent */
    size_t nsends, sends_cap;
    bool program_started_mpi; /* then the program ends it, not ranks_close */
} mpi_ranks;

static int region_tag(const mpi_ranks *m, uint64_t index)
{
    return TAG_REGION + (int)(index % (uint64_t)m->tag_span);
}

/* Receives n bytes sent in pieces into p, or drops them (p NULL). */
static void recv_bytes(void *p, uint64_t n, int src, int tag)
{
    char *c = p ? p : malloc((size_t)(n < PIECE ? n : PIECE) + 1);
    if (!c)
        MPI_Abort(MPI_COMM_WORLD, 1); /* the sender would wait forever */
    do {
        const int k = (int)(n < PIECE ? n : PIECE);
        MPI_Recv(c, k, MPI_BYTE, src, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        c += p ? k : 0;
        n -= (uint64_t)k;
    } while (n > 0);
    if (!p)
        free(c);
}

enum { REGION_ARRAYS = 5 };

/* The bytes of a region's arrays after its header, in the order sent. */
static void region_arrays(const region_header *h, uint64_t bytes[REGION_ARRAYS])
{
    bytes[0] = bytes[1] = bytes[2] = h->ncells * sizeof(uint32_t);
    bytes[3] = h->nexits * (uint64_t)h->box.dim * sizeof(int64_t);
    bytes[4] = h->nexits * sizeof(uint32_t);
}

/* ---- a worker ------------------------------------------------------------ */

/* Waits for a message from rank src, asleep between looks: a blocking
 * probe spins, and on a host with more ranks than cores a worker waiting
 * for its next boxes took the core rank 0's joins needed (3 ranks of the
 * Table 4.1 4x4 split on 2 cores: 180-196 ms against 99-103 on 2 ranks). */
static void wait_for(int src, MPI_Status *s)
{
    const struct timespec pause = {0, 50000};
    for (int flag = 0;;) {
        MPI_Iprobe(src, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, s);
        if (flag)
            return;
        nanosleep(&pause, NULL);
    }
}

static bool stop_pending(void)
{
    int flag = 0;
    MPI_Iprobe(0, TAG_STOP, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
    return flag != 0;
}

/* A region on its way to rank 0: sent without waiting, so that the worker
 * solves its next box meanwhile; kept until rank 0 has taken it. */
typedef struct outgoing {
    region_header *h; /* on the heap: MPI reads it while the record moves */
    cm_region r;
    uint32_t *tree;
    MPI_Request *req;
    int nreq;
} outgoing;

static int pieces(uint64_t n) { return n == 0 ? 1 : (int)((n + PIECE - 1) / PIECE); }

/* Starts sending box q's region (st CM_OK) or why it failed; o takes r. */
static cm_status start_send(const mpi_ranks *m, const box_request *q, cm_region *r, cm_status st,
                            const char *why, outgoing *o)
{
    memset(o, 0, sizeof *o);
    region_header *h = o->h = calloc(1, sizeof *h);
    if (!h)
        return CM_ENOMEM;
    h->index = q->index;
    h->status = st;
    snprintf(h->msg, sizeof h->msg, "%s", why);
    if (st == CM_OK) {
        h->ncells = r->ncells;
        h->nexits = r->nexits;
        h->exits_recorded = r->exits_recorded;
        h->ngroups = r->ngroups;
        h->box = r->box;
        o->r = *r;
        memset(r, 0, sizeof *r);
        if (!(o->tree = malloc(o->r.nexits * sizeof *o->tree + 1)))
            return CM_ENOMEM;
        cm_region_trees(&o->r, o->tree);
    }
    uint64_t bytes[REGION_ARRAYS];
    region_arrays(h, bytes);
    int n = 1;
    for (int a = 0; st == CM_OK && a < REGION_ARRAYS; a++)
        n += pieces(bytes[a]);
    if (!(o->req = malloc((size_t)n * sizeof *o->req)))
        return CM_ENOMEM;
    const int tag = region_tag(m, q->index);
    MPI_Isend(h, (int)sizeof *h, MPI_BYTE, 0, tag, MPI_COMM_WORLD, &o->req[o->nreq++]);
    const void *arrays[REGION_ARRAYS] = {o->r.image, o->r.group, o->r.step, o->r.exit_target,
                                         o->tree};
    for (int a = 0; st == CM_OK && a < REGION_ARRAYS; a++) {
        const char *c = arrays[a];
        uint64_t left = bytes[a];
        do { /* an empty array is one empty message */
            const int k = (int)(left < PIECE ? left : PIECE);
            MPI_Isend(c, k, MPI_BYTE, 0, tag, MPI_COMM_WORLD, &o->req[o->nreq++]);
            c += k;
            left -= (uint64_t)k;
        } while (left > 0);
    }
    return CM_OK;
}

/* Whether o has gone (wait: once it has); its memory is freed then. */
static bool sent(outgoing *o, bool wait)
{
    int done = 1;
    if (wait)
        MPI_Waitall(o->nreq, o->req, MPI_STATUSES_IGNORE);
    else
        MPI_Testall(o->nreq, o->req, &done, MPI_STATUSES_IGNORE);
    if (done) {
        free(o->req);
        free(o->h);
        free(o->tree);
        cm_region_free(&o->r);
    }
    return done != 0;
}

/* Regions a worker holds while rank 0 has not taken them: at most this
 * many, then it waits for the oldest. */
#define OUTGOING_MAX 8

typedef struct outbox {
    outgoing v[OUTGOING_MAX];
    int n;
} outbox;

/* While a worker solves, its sends go on: MPI moves a message between
 * hosts only within MPI calls (cm_scm_solve's progress callback, on the
 * thread that called it). */
static int keep_sending(void *user, const char *phase, double fraction)
{
    outbox *o = user;
    (void)phase;
    (void)fraction;
    for (int k = 0; k < o->n; k++) {
        int done;
        MPI_Testall(o->v[k].nreq, o->v[k].req, &done, MPI_STATUSES_IGNORE);
    }
    return 0;
}

static cm_status serve(solve_ranks *rk, const cm_model *model, const cm_lattice *lat,
                       int max_steps, int threads, char *msg, size_t msg_size)
{
    const mpi_ranks *m = (const mpi_ranks *)rk;
    outbox box = {.n = 0};
    outgoing *out = box.v;
    const cm_scm_options opt = {.max_steps = max_steps,
                                .threads = threads,
                                .record_exits = 1,
                                .progress = keep_sending,
                                .user = &box};
    for (;;) {
        MPI_Status s;
        wait_for(0, &s);
        if (s.MPI_TAG == TAG_STOP) {
            int32_t status;
            MPI_Recv(&status, 1, MPI_INT32_T, 0, TAG_STOP, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            for (int i = 0; i < box.n; i++) /* rank 0 drains them */
                sent(&out[i], true);
            MPI_Send(NULL, 0, MPI_BYTE, 0, TAG_DONE, MPI_COMM_WORLD);
            return status == CM_OK ? CM_OK
                                   : cm_fail((cm_status)status, msg, msg_size, "rank 0 failed");
        }
        int count;
        MPI_Get_count(&s, MPI_BYTE, &count);
        box_request *v = malloc((size_t)count + 1);
        if (!v) { /* its boxes would never come back */
            fprintf(stderr, "cellmap solve: rank %d: out of memory for %d bytes\n", rk->rank,
                    count);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        MPI_Recv(v, count, MPI_BYTE, 0, TAG_BOXES, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        /* once rank 0 stops (it failed), the boxes left are not solved */
        for (size_t i = 0; i < (size_t)count / sizeof *v && !stop_pending(); i++) {
            int kept = 0; /* the regions rank 0 has not taken yet, oldest first */
            for (int k = 0; k < box.n; k++)
                if (!sent(&out[k], false))
                    out[kept++] = out[k];
            box.n = kept;
            if (box.n == OUTGOING_MAX) {
                sent(&out[0], true);
                memmove(out, out + 1, --box.n * sizeof *out);
            }
            char why[256] = "";
            cm_region r;
            cm_status st = cm_region_alloc(&r, &v[i].box, why, sizeof why);
            if (st == CM_OK)
                st = cm_scm_solve(model, lat, &opt, &r, why, sizeof why);
            if (start_send(m, &v[i], &r, st, why, &out[box.n]) != CM_OK) {
                fprintf(stderr, "cellmap solve: rank %d: out of memory\n", rk->rank);
                MPI_Abort(MPI_COMM_WORLD, 1);
            }
            box.n++;
            cm_region_free(&r);
        }
        free(v);
    }
}

/* ---- rank 0 ------------------------------------------------------------- */

/* Worker w's oldest box held is no longer (lock held). */
static void forget_oldest(mpi_ranks *m, int w)
{
    uint64_t *given = &m->given[(size_t)w * WORKER_QUEUE];
    memmove(given, given + 1, (size_t)--m->held[w] * sizeof *given);
}

/* Forgets worker w's boxes whose regions have arrived (lock held): a
 * worker sends its regions in the order it was given the boxes, so the
 * oldest comes first. A region that arrived waits for its join, and the
 * worker goes on. */
static void note_arrivals(mpi_ranks *m, int w)
{
    for (int flag = 1; flag && m->held[w] > 0;) {
        MPI_Iprobe(w, region_tag(m, m->given[(size_t)w * WORKER_QUEUE]), MPI_COMM_WORLD, &flag,
                   MPI_STATUS_IGNORE);
        if (flag)
            forget_oldest(m, w);
    }
}

/* The worker holding the fewest boxes, if it has room (lock held), or 0.
 * Room is WORKER_QUEUE boxes, and no more than an even share of the
 * boxes still to claim (from box b of the call): else a call of few boxes
 * would go to the workers whole while rank 0 waits for them. */
static int least_held(mpi_ranks *m, uint32_t b)
{
    const uint32_t left = m->nboxes - b, size = (uint32_t)m->pub.size;
    const int share = (int)((left + size - 1) / size);
    const int limit = share < WORKER_QUEUE ? share : WORKER_QUEUE;
    int w = 0;
    for (int k = 1; k < m->pub.size; k++) {
        note_arrivals(m, k);
        if (m->held[k] < limit && (w == 0 || m->held[k] < m->held[w]))
            w = k;
    }
    return w;
}

/* Frees the box requests sent (lock held); all of them: waits for them. */
static void reap_sends(mpi_ranks *m, bool all)
{
    size_t kept = 0;
    for (size_t i = 0; i < m->nsends; i++) {
        int done = 1;
        if (all)
            MPI_Wait(&m->sends[i]->req, MPI_STATUS_IGNORE);
        else
            MPI_Test(&m->sends[i]->req, &done, MPI_STATUS_IGNORE);
        if (done)
            free(m->sends[i]);
        else
            m->sends[kept++] = m->sends[i];
    }
    m->nsends = kept;
}

static bool room(void *user)
{
    mpi_ranks *m = user;
    pthread_mutex_lock(&m->lock);
    const bool some = m->claimed < m->nboxes && least_held(m, m->claimed) != 0;
    pthread_mutex_unlock(&m->lock);
    return some;
}

/* Sends box b of the call to the worker with most room, if one has room
 * (and there is memory for the request: else rank 0 solves it). */
static bool take(void *user, uint32_t b)
{
    mpi_ranks *m = user;
    pthread_mutex_lock(&m->lock);
    reap_sends(m, false);
    m->claimed = b + 1;
    const int w = least_held(m, b);
    pending_send *ps = NULL;
    if (w != 0 && (m->nsends < m->sends_cap ||
                   cm_grow((void **)&m->sends, &m->sends_cap, m->nsends + 1,
                           sizeof *m->sends) == CM_OK))
        ps = malloc(sizeof *ps);
    if (ps) {
        ps->q = (box_request){m->first + b, m->boxes[b]};
        MPI_Isend(&ps->q, (int)sizeof ps->q, MPI_BYTE, w, TAG_BOXES, MPI_COMM_WORLD, &ps->req);
        m->sends[m->nsends++] = ps;
        m->holder[b] = w;
        m->given[(size_t)w * WORKER_QUEUE + m->held[w]++] = m->first + b;
        m->pub.bytes_sent += sizeof ps->q;
    }
    m->pub.regions_by_rank[ps ? w : 0]++;
    pthread_mutex_unlock(&m->lock);
    return ps != NULL;
}

/* A call's boxes: none given to a worker yet. */
static cm_status ask(void *user, const cm_box *boxes, uint32_t n, char *msg, size_t msg_size)
{
    mpi_ranks *m = user;
    int *holder = calloc((size_t)n + 1, sizeof *holder);
    if (!holder)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u boxes", n);
    pthread_mutex_lock(&m->lock);
    free(m->holder);
    m->holder = holder;
    m->boxes = boxes;
    m->nboxes = n;
    m->claimed = 0;
    m->first = m->asked;
    m->asked += n;
    pthread_mutex_unlock(&m->lock);
    return CM_OK;
}

/* Receives the region index from rank src into r, its trees' sizes into
 * a new *tree (lock held). */
static cm_status receive_region(mpi_ranks *m, int src, uint64_t index, cm_region *r,
                                uint32_t **tree, char *msg, size_t msg_size)
{
    const int tag = region_tag(m, index);
    region_header h;
    MPI_Recv(&h, (int)sizeof h, MPI_BYTE, src, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    m->pub.bytes_received += sizeof h;
    if (h.status != CM_OK)
        return cm_fail((cm_status)h.status, msg, msg_size, "rank %d: %s", src, h.msg);
    if (h.index != index)
        return cm_fail(CM_EFORMAT, msg, msg_size, "rank %d sent region %llu for region %llu", src,
                       (unsigned long long)h.index, (unsigned long long)index);
    uint64_t bytes[REGION_ARRAYS];
    region_arrays(&h, bytes);
    cm_status st = cm_region_alloc(r, &h.box, msg, msg_size);
    if (st == CM_OK &&
        (!(r->exit_target = malloc(bytes[3] + 1)) || !(*tree = malloc(bytes[4] + 1))))
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                     (unsigned long long)h.nexits);
    if (st != CM_OK) { /* the arrays on their way could not be taken */
        fprintf(stderr, "cellmap solve: %s\n", msg);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    r->nexits = h.nexits;
    r->exits_recorded = h.exits_recorded;
    r->ngroups = h.ngroups;
    void *arrays[REGION_ARRAYS] = {r->image, r->group, r->step, r->exit_target, *tree};
    for (int a = 0; a < REGION_ARRAYS; a++) {
        recv_bytes(arrays[a], bytes[a], src, tag);
        m->pub.bytes_received += bytes[a];
    }
    m->pub.regions_received++;
    return CM_OK;
}

static cm_status fetch(void *user, uint32_t b, cm_region *r, uint32_t **tree, bool *got,
                       char *msg, size_t msg_size)
{
    mpi_ranks *m = user;
    const uint64_t index = m->first + b;
    int flag = 0;
    pthread_mutex_lock(&m->lock);
    const int src = m->holder[b];
    MPI_Iprobe(src, region_tag(m, index), MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
    const cm_status st = flag ? receive_region(m, src, index, r, tree, msg, msg_size) : CM_OK;
    if (flag && m->held[src] > 0 && m->given[(size_t)src * WORKER_QUEUE] == index)
        forget_oldest(m, src); /* its arrival was not noted before */
    pthread_mutex_unlock(&m->lock);
    *got = flag != 0;
    return st;
}

/* Takes what worker w still sends before it stops: whole regions, dropped. */
static void drain(int w)
{
    for (;;) {
        MPI_Status s;
        wait_for(w, &s);
        if (s.MPI_TAG == TAG_DONE) {
            MPI_Recv(NULL, 0, MPI_BYTE, w, TAG_DONE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            return;
        }
        region_header h;
        MPI_Recv(&h, (int)sizeof h, MPI_BYTE, w, s.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        uint64_t bytes[REGION_ARRAYS];
        region_arrays(&h, bytes);
        for (int a = 0; h.status == CM_OK && a < REGION_ARRAYS; a++)
            recv_bytes(NULL, bytes[a], w, s.MPI_TAG);
    }
}

static cm_status stop(solve_ranks *rk, cm_status status)
{
    mpi_ranks *m = (mpi_ranks *)rk;
    const int32_t s = status;
    for (int w = 1; w < rk->size; w++)
        MPI_Send(&s, 1, MPI_INT32_T, w, TAG_STOP, MPI_COMM_WORLD);
    for (int w = 1; w < rk->size; w++)
        drain(w);
    reap_sends(m, true); /* received: every worker read up to the stop */
    return status;
}

/* ---- every rank --------------------------------------------------------- */

/* A hash of the program's file and arguments, and of what a rank solves. */
#define HASH_START UINT64_C(1469598103934665603)

/* FNV-1a of n bytes, going on from h. */
static uint64_t hash_bytes(uint64_t h, const void *p, size_t n)
{
    for (const unsigned char *c = p; n > 0; n--, c++)
        h = (h ^ *c) * UINT64_C(1099511628211);
    return h;
}

static void ready(solve_ranks *rk, bool ok, const char *what, bool *all_ok, int *first_failed,
                  bool *differs)
{
    uint64_t *all = malloc((size_t)rk->size * 2 * sizeof *all);
    if (!all)
        MPI_Abort(MPI_COMM_WORLD, 1); /* the others wait for this rank */
    const uint64_t mine[2] = {ok, what ? hash_bytes(HASH_START, what, strlen(what)) : 0};
    MPI_Allgather(mine, 2, MPI_UINT64_T, all, 2, MPI_UINT64_T, MPI_COMM_WORLD);
    *all_ok = true;
    *first_failed = -1;
    *differs = false;
    for (int k = 0; k < rk->size && *all_ok; k++)
        if (!all[2 * k] || all[2 * k + 1] != all[1]) {
            *all_ok = false;
            *first_failed = k;
            *differs = all[2 * k] != 0;
        }
    free(all);
    rk->readied = true;
}

/* A hash of this program's file: ranks that run another build differ. */
static uint64_t program_hash(const char *program)
{
    uint64_t h = HASH_START;
    const int fd = open(program ? program : "/proc/self/exe", O_RDONLY);
    if (fd < 0)
        return 0;
    unsigned char buf[1 << 16];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0)
        h = hash_bytes(h, buf, (size_t)n);
    close(fd);
    return h;
}

/* The arguments, each with its terminating 0 (argv[0], the path, aside). */
static uint64_t args_hash(int argc, char **argv)
{
    uint64_t h = HASH_START;
    for (int i = 1; argv && i < argc; i++)
        h = hash_bytes(h, argv[i], strlen(argv[i]) + 1);
    return h;
}

/* Step 1: every rank runs rank 0's program with rank 0's arguments. */
static cm_status same_everywhere(const solve_ranks *rk, const char *program, int argc,
                                 char **argv, char *msg, size_t msg_size)
{
    const uint64_t mine[2] = {program_hash(program), args_hash(argc, argv)};
    uint64_t *all = malloc((size_t)rk->size * sizeof mine);
    if (!all)
        MPI_Abort(MPI_COMM_WORLD, 1);
    MPI_Allgather(mine, 2, MPI_UINT64_T, all, 2, MPI_UINT64_T, MPI_COMM_WORLD);
    cm_status st = CM_OK;
    for (int k = 1; k < rk->size && st == CM_OK; k++)
        if (all[2 * k] != all[0])
            st = cm_fail(CM_EINVAL, msg, msg_size,
                         "rank %d runs another cellmap program than rank 0 (its file differs): "
                         "install the same build of cellmap on every host",
                         k);
        else if (all[2 * k + 1] != all[1])
            st = cm_fail(CM_EINVAL, msg, msg_size,
                         "rank %d was given other arguments than rank 0: start every rank with "
                         "the same command line",
                         k);
    free(all);
    return st;
}

cm_status ranks_open(int *argc, char ***argv, const char *program, solve_ranks **out, char *msg,
                     size_t msg_size)
{
    *out = NULL;
    int provided = MPI_THREAD_SINGLE, started = 0;
    MPI_Initialized(&started);
    if (started)
        MPI_Query_thread(&provided);
    else if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
        return cm_fail(CM_EIO, msg, msg_size, "MPI did not start");
    mpi_ranks *m = calloc(1, sizeof *m);
    if (!m)
        MPI_Abort(MPI_COMM_WORLD, 1);
    m->program_started_mpi = started != 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &m->pub.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &m->pub.size);
    int *tag_ub = NULL, found = 0;
    MPI_Comm_get_attr(MPI_COMM_WORLD, MPI_TAG_UB, &tag_ub, &found);
    m->tag_span = (found && tag_ub ? *tag_ub : 32767) - TAG_REGION;
    m->held = calloc((size_t)m->pub.size, sizeof *m->held);
    m->given = calloc((size_t)m->pub.size * WORKER_QUEUE, sizeof *m->given);
    m->pub.regions_by_rank = calloc((size_t)m->pub.size, sizeof *m->pub.regions_by_rank);
    if (!m->held || !m->given || !m->pub.regions_by_rank)
        MPI_Abort(MPI_COMM_WORLD, 1);
    pthread_mutex_init(&m->lock, NULL);
    m->pub.ready = ready;
    m->pub.serve = serve;
    m->pub.stop = stop;
    m->pub.source = (cm_region_source){ask, room, take, fetch, (uint32_t)m->pub.size, m};
    *out = &m->pub;
    if (provided < MPI_THREAD_SERIALIZED)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "this MPI gives threads level %d; cellmap needs MPI_THREAD_SERIALIZED%s",
                       provided,
                       started ? " (start MPI with MPI_Init_thread at that level or above)" : "");
    return same_everywhere(&m->pub, program, argc ? *argc : 0, argv ? *argv : NULL, msg,
                           msg_size);
}

void ranks_close(solve_ranks *rk, bool ok)
{
    if (!rk)
        return;
    bool all_ok, differs;
    int failed;
    if (!rk->readied)
        ready(rk, ok, NULL, &all_ok, &failed, &differs);
    mpi_ranks *m = (mpi_ranks *)rk;
    const bool finalize = !m->program_started_mpi;
    pthread_mutex_destroy(&m->lock);
    for (size_t i = 0; i < m->nsends; i++) /* none once stop() ran */
        free(m->sends[i]);
    free(m->holder);
    free(m->held);
    free(m->given);
    free(m->sends);
    free(m->pub.regions_by_rank);
    free(m);
    if (finalize)
        MPI_Finalize();
}

/* libcellmap-mpi.so's entry points (lib/ranks.h). */
cm_status cm_mpi_ranks_open(const char *program, solve_ranks **out, char *msg, size_t msg_size);
void cm_mpi_ranks_close(solve_ranks *rk, bool ok);

cm_status cm_mpi_ranks_open(const char *program, solve_ranks **out, char *msg, size_t msg_size)
{
    return ranks_open(NULL, NULL, program, out, msg, msg_size);
}

void cm_mpi_ranks_close(solve_ranks *rk, bool ok) { ranks_close(rk, ok); }
