/* cellmap/cluster.h - a cluster of regions on one lattice: immutable region
 * arrays, the node graph that joins them, paging, and readers that resolve
 * cells (thesis 4.6.2, Algorithms C.3-C.7, generalised from two solutions
 * to any number of regions in any dimension).
 *
 * A region's arrays (cellmap/scm.h) are written by its SCM and never change
 * afterwards. Its *nodes* are the cells whose image leaves the region: node
 * k of a region is the cell of its exit k (image CM_IMAGE_EXIT_BASE + k).
 * Every other cell whose chain ends there (the node's tree) holds
 * group = CM_NODE_REF | k and step = its depth in the tree + 1 (the node
 * itself has step 1). Cells of the region's own groups hold cluster-wide
 * group ids (the region's group g becomes base + g when it joins) and final
 * steps; cells whose chains end in the world's sink hold group 0.
 *
 * Nodes have cluster-wide ids: a region's node k is node_base + k. The node
 * table says where each node's exit leads once a region holds its target
 * cell, and what that means: a final group and step, or the tree of another
 * node (a link, with the steps to that node's cell), or a cycle through
 * several regions (a straddling group). A cell is resolved when read: its
 * node's outcome plus its depth. Links never change once set, so resolution
 * shortens chains of links as it follows them (cm_cluster_resolve).
 *
 * Cells in the tree of a node on a straddling cycle count their steps to the
 * cycle, which can enter the tree above the node: such a node records the
 * cell where the cycle enters its tree, and readers walk (cm_cluster_flatten).
 * The nodes linked into a cycle node's tree while it was open are listed
 * with it and made final when the cycle closes, so that no later resolution
 * needs a region's cells.
 *
 * Open nodes (exits that still leave the cluster) carry weights: the cells
 * whose sequences leave through them, which basins and adaptive extension
 * count. Each region lists its open nodes with their exits' cells (its
 * open list), paged with its node table when the owner can read it back
 * (open_in); a brick index names, for each brick of the lattice, the
 * regions whose open nodes lead into it (the open nodes themselves when
 * no lists are kept). Node tables, like cell arrays, are paged.
 *
 * The invariant (tests/test_cluster.c): for regions tiling a box, the
 * flattened cluster equals cm_scm_solve on the box, cell by cell, up to the
 * numbering of groups. One cluster is used from one thread at a time; joins
 * and readers use c->threads threads and give the same result for any.
 */
#ifndef CM_CLUSTER_H
#define CM_CLUSTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cellmap/bricks.h"
#include "cellmap/classify.h"
#include "cellmap/idmap.h"
#include "cellmap/scm.h"

/* Node records are saved in chunks of this many, each rewritten only when
 * one of its nodes changed. */
#define CM_NODE_CHUNK 4096

/* cm_node.next values other than a node id */
#define CM_NODE_OPEN UINT32_C(0xFFFFFFFF)  /* the exit leads out of the cluster */
#define CM_NODE_FINAL UINT32_C(0xFFFFFFFE) /* group and step of the cell are known */
#define CM_NODE_CYCLE UINT32_C(0xFFFFFFFD) /* the cell is on a straddling cycle */
#define CM_NODE_MAX UINT32_C(0xFFFFFFF0)   /* node ids stay below */

/* One node (public: read by the store and the readers; written by joins). */
typedef struct cm_node {
    uint32_t next;   /* a node id: the exit lands in that node's tree; or a mark above */
    uint32_t dist;   /* next a node: steps from this cell to next's cell; FINAL: this
                        cell's step; CYCLE: local index of the cell where the cycle
                        enters this node's tree */
    uint32_t group;  /* FINAL, CYCLE: the cell's group */
    uint32_t target; /* local index of the exit's target cell in its region, once linked */
    uint32_t tree;   /* cells of the node's tree, itself included */
    /* the nodes linked into this node's tree while its sequences still left
     * the cluster: a list through first_in and their sibling fields
     * (CM_NODE_OPEN ends it), so that they can be settled when this node
     * turns out to be on a straddling cycle */
    uint32_t first_in, sibling;
    /* private: resolution state, rebuilt from the above when a table is read */
    uint32_t up;      /* a node further along the chain, or a mark: FINAL (group and
                         up_dist known), OPEN (this node is open), CYCLE (a cycle node:
                         the chains that reach it are settled through next links) */
    uint32_t up_dist; /* steps to up's cell; FINAL: this cell's step */
} cm_node;

typedef struct cm_cluster_region {
    cm_region r;        /* arrays NULL while the region is paged out */
    cm_node *nodes;     /* read-only: its r.nexits nodes (cm_cluster_node) */
    uint32_t node_base; /* id of the node of exit 0 */
    int written;        /* read-only: the owner holds its arrays (cm_cluster_saved) */
    int nodes_dirty;    /* read-only: node records changed since the owner saved them */
    uint8_t *dirty_chunks; /* read-only: per CM_NODE_CHUNK nodes, whether one of them did */
    /* private: the region's open nodes indexed as escapes, in node order
     * (open_local[i]: the exit, open_cells[i * dim ..]: its target), some
     * of them linked since (open_stale of them); open_dirty (read-only):
     * one changed since the owner saved them (cm_cluster_open_nodes) */
    uint32_t *open_local;
    int64_t *open_cells;
    /* private: while the node table is paged out, the weight of each
     * listed node, bit 63 set while it is still open (else its record
     * holds it) */
    uint64_t *open_weight;
    uint64_t nopen, open_cap, open_stale;
    int open_dirty;
    /* private: the list is paged out with the node table (nopen: the
     * nodes saved, all open); read back through open_in */
    int open_paged;
    uint64_t last_used; /* private: paging clock of the last acquire of the cells */
    uint64_t nodes_used; /* private: and of the last use of the node table */
    int pinned;          /* private: its cells are needed by the join under way */
} cm_cluster_region;

/* A periodic cell of a group made since the owner last took them. */
typedef struct cm_group_cell {
    uint32_t group;
    int64_t cell[CM_MAX_DIM];
} cm_group_cell;

/* Reads back the arrays of a paged-out region: r has box, ncells, nexits
 * and ngroups set and NULL arrays; the pager allocates and fills image,
 * group, step and exit_target exactly as they were saved. */
typedef cm_status (*cm_page_in_fn)(void *user, uint32_t region, cm_region *r, char *msg,
                                   size_t msg_size);

/* Reads back the saved fields (next, dist, group, target, tree) of region
 * k's n nodes into nodes[0..n) exactly as they were saved. */
typedef cm_status (*cm_nodes_in_fn)(void *user, uint32_t region, cm_node *nodes, uint64_t n,
                                    char *msg, size_t msg_size);
/* Reads a paged-out region's groups alone into group[ncells], checked
 * (cm_groups_check), leaving the region paged out: for readers of labels,
 * which need no image, step or exit table. */
typedef cm_status (*cm_groups_in_fn)(void *user, uint32_t region, uint32_t *group, char *msg,
                                     size_t msg_size);

struct cm_cluster;

/* Reads back region k's open nodes as the owner saved them from
 * cm_cluster_open_nodes: *n of them, their exits ascending in *local, their
 * weights and target cells (dim each), in new arrays the cluster takes
 * (NULL when *n is 0). */
typedef cm_status (*cm_open_in_fn)(void *user, uint32_t region, uint32_t **local,
                                   uint64_t **weight, int64_t **cells, uint64_t *n, char *msg,
                                   size_t msg_size);

/* Saves a region that was never saved, so that it can be evicted (also in
 * the middle of a join: the owner keeps the write in the transaction that
 * its next commit ends). */
typedef cm_status (*cm_page_out_fn)(void *user, const struct cm_cluster *c, uint32_t region,
                                    char *msg, size_t msg_size);

typedef struct cm_cluster {
    cm_lattice lat;                   /* read-only */
    cm_cluster_region *regions;       /* read-only: in the order they were joined */
    uint32_t nregions;                /* read-only */
    uint32_t ngroups;                 /* read-only: cluster-wide group ids 1..ngroups */
    int threads;                      /* public: OpenMP threads; 0: the OpenMP default */
    /* public: 1 after cm_cluster_init: each region keeps its exit table
     * and lists its open nodes with their targets, for an owner to save
     * (cm_cluster_open_nodes) and for the images of cm_cluster_flatten. A
     * cluster that no one saves and whose images no one reads (solve
     * without a database) sets 0: a joined region then drops its exit
     * table (16 bytes per exit in 2-D) and open lists are not kept. Set
     * before the first region: the index of escapes is made for one or
     * the other. */
    int keep_exits;
    /* read-only: the regions hold resolved cells (a file of version 2 or
     * 3): a sink cell does not say which exit its sequence leaves by */
    int resolved_cells;
    /* read-only: its open nodes' index was released (cm_cluster_release_open) */
    int open_released;
    uint64_t nnodes;                  /* read-only: nodes of all regions */
    uint64_t cells;                   /* read-only: cells of all regions */
    uint64_t *basin;                  /* read-only: cells of group g (1..ngroups); [0] unused */
    uint8_t *basin_dirty;             /* read-only: basin[g] changed since cm_cluster_saved */
    cm_group_cell *new_periodic;   /* read-only: of groups made since cm_cluster_saved */
    uint64_t nnew_periodic;           /* read-only */
    uint32_t saved_groups;            /* read-only: ngroups at cm_cluster_saved */
    /* Paging, off while page_in is NULL. cm_cluster_acquire reads a
     * region's cells back through page_in and first evicts other regions'
     * cells (those the upcoming boxes need last, then the least recently
     * used, first) so that the resident cell arrays and exit tables stay
     * within mem_budget (more only while one region alone is bigger); a
     * region never saved is saved through page_out first (kept resident if
     * there is none). cm_cluster_trim also evicts clean node tables, read
     * back on use through nodes_in, and with open_in the clean open lists
     * of regions whose node tables are out, to keep the two within
     * mem_budget / 4, or beyond it within the room the cells leave (cells
     * and tables within mem_budget * 5 / 4); more only within a join, which
     * never evicts them. Without open_in, open lists stay in memory: 28
     * bytes an open node in 2-D, which a long explore session gains by the
     * million. */
    cm_page_in_fn page_in;   /* public */
    cm_page_out_fn page_out; /* public */
    cm_nodes_in_fn nodes_in; /* public: reads node tables back (they are evicted clean) */
    cm_open_in_fn open_in;   /* public: reads open lists back (they are evicted clean) */
    cm_groups_in_fn groups_in; /* public: reads a region's groups alone (NULL: none) */
    void *pager;             /* public */
    uint64_t mem_budget;     /* public: 0: no limit */
    /* public: bytes its owner holds beside the cluster, which the budget
     * makes room for too: regions solved ahead of their joins (a join adds
     * them to what was there and takes them off after), a pass over the
     * cluster's exits (cm_cluster_exits_room) */
    uint64_t mem_reserved;
    /* public: the boxes still to join, in order, if known (NULL: none).
     * Eviction keeps the regions next to the first of them, where their
     * sequences most likely land, and evicts the others first. */
    const cm_box *upcoming;
    uint32_t nupcoming;
    /* public: where cm_cluster_solve_boxes gets regions solved elsewhere
     * (cellmap/join.h); NULL: it solves every box */
    const struct cm_region_source *source;
    /* private */
    uint64_t cap, basin_cap, periodic_cap, clock;
    cm_idmap open;   /* weights of open nodes no open list holds, their node tables paged out */
    uint64_t evicted_since_trim; /* bytes evicted since the heap was last trimmed */
    uint32_t *node_blocks; /* the region of every 1024th node id */
    uint64_t node_blocks_cap;
    uint32_t *node_bases; /* regions[k].node_base for every k, packed for cm_cluster_node_region */
    uint64_t node_bases_cap;
    uint32_t *chain; /* nodes walked while settling */
    uint64_t chain_cap;
    cm_bricks *region_bricks; /* brick -> regions meeting it */
    cm_bricks *escape_bricks; /* brick of the target -> regions (keep_exits) or open nodes */
    uint32_t *big;            /* regions too big for the brick index */
    uint64_t nbig, big_cap;
} cm_cluster;

/* An open node whose exit leads into a box, and the local index of the
 * exit's target cell in the box. */
typedef struct cm_escape {
    uint32_t node, cell;
} cm_escape;

void cm_cluster_init(cm_cluster *c, const cm_lattice *lat);
void cm_cluster_free(cm_cluster *c);

/* Releases what the cluster keeps of its open nodes (the weights of paged
 * out ones, the escape index, the regions' open lists), for an owner that from here on only reads its cells and node
 * tables (flattening, labels): a region added (a join) or a commit is
 * refused afterwards (CM_EINVAL), and it has no escapes
 * (cm_cluster_each_escape, cm_cluster_exits). */
void cm_cluster_release_open(cm_cluster *c);

/* Threads a join or reader uses: c->threads, or the OpenMP default. */
int cm_cluster_threads(const cm_cluster *c);

/* The node table of a region solved with record_exits, before it joins a
 * cluster: every node open, weighing its tree (r->nexits + 1 records, the
 * caller's to free or hand to cm_cluster_add_region). Reads r only, so
 * another thread can make it while the cluster joins. */
cm_status cm_region_nodes(const cm_region *r, cm_node **out);

/* The size of each of r's nodes' trees (cells whose chains end on the
 * node, itself included) into tree[0..r->nexits): what the node table
 * takes of r's cells. Reads r only. */
void cm_region_trees(const cm_region *r, uint32_t *tree);

/* cm_region_nodes from those sizes (tree: r->nexits of them, from
 * cm_region_trees, as another process sends them): no cell is read. */
cm_status cm_region_nodes_of_trees(const cm_region *r, const uint32_t *tree, cm_node **out);

/* Adds region r (solved with record_exits on the cluster's lattice; the
 * cluster takes its arrays, r is zeroed) without linking anything: its own
 * groups take the next ids, its nodes are open, its periodic cells are
 * noted as new. nodes: its node table from cm_region_nodes, which the
 * cluster takes in any case, or NULL: made here. CM_EINVAL if it overlaps a
 * region. The join module (cellmap/join.h) then links. */
cm_status cm_cluster_add_region(cm_cluster *c, cm_region *r, cm_node *nodes, char *msg,
                                size_t msg_size);

/* Restores a region saved by an owner, paged out: its record (box, ncells,
 * nexits, ngroups) and its nodes' saved fields (next, dist, group, target,
 * tree for each of nexits nodes), or NULL: its node table stays paged out
 * (read back through nodes_in). Then one of the two below. */
cm_status cm_cluster_restore(cm_cluster *c, const cm_region *record, const cm_node *nodes,
                             char *msg, size_t msg_size);

/* Checks region k's node records as read from a file (nodes[0..nexits)):
 * links to nodes of the cluster (with a target cell in that node's
 * region), marks the format knows, groups up to groups, trees within the
 * region, lists of linked nodes through nodes of the cluster.
 * CM_EFORMAT naming the node otherwise. */
cm_status cm_cluster_check_nodes(const cm_cluster *c, uint32_t k, const cm_node *nodes,
                                 uint32_t groups, char *msg, size_t msg_size);

/* After the last cm_cluster_restore, every node table given: the open
 * nodes, their weights (resolving every node) and their index from the exit
 * tables (exits[k]: region k's, nexits * dim cells, which the caller keeps).
 * groups: the saved group count; basin: the saved cells per group (groups +
 * 1 entries, [0] unused). */
cm_status cm_cluster_restored(cm_cluster *c, uint32_t groups, const uint64_t *basin,
                              int64_t *const *exits, char *msg, size_t msg_size);

/* The same from the open nodes as saved, no node table read: first
 * cm_cluster_restored_open, then cm_cluster_restored_escapes for each
 * region's saved open nodes, regions in order: n of them in node order,
 * ids[i] with weight weights[i] and its exit's target cell cells[i * dim
 * ..]. With open_in, the open lists are left in the file (read back on
 * use) and only indexed. */
cm_status cm_cluster_restored_open(cm_cluster *c, uint32_t groups, const uint64_t *basin,
                                   char *msg, size_t msg_size);
cm_status cm_cluster_restored_escapes(cm_cluster *c, const uint32_t *ids, const uint64_t *weights,
                                      const int64_t *cells, uint64_t n, char *msg,
                                      size_t msg_size);

/* The region holding the cell and the cell's local index, or -1. O(1). */
int64_t cm_cluster_locate(const cm_cluster *c, const int64_t *cell, uint64_t *local);

/* The order in which to look up n cells (dim coordinates each) so that a
 * paged cluster reads each region once: *order (n entries, the caller's to
 * free) lists the cells' indices region by region (in region order, cells
 * of no region last), in their given order within a region. O(n). */
cm_status cm_cluster_region_order(const cm_cluster *c, const int64_t *cells, uint64_t n,
                                  uint64_t **order);

/* The resolved groups (0: the sink) of n cells (dim coordinates each) into
 * group[0..n), CM_GROUP_NONE where no region holds the cell: looked up
 * region by region (cm_cluster_region_order), reading a paged out region
 * (and node tables) back once. A cm_cells_group_fn (cellmap/attractors.h)
 * with user the cluster. */
cm_status cm_cluster_cells_group(void *cluster, const int64_t *cells, uint64_t n,
                                 uint32_t *group, char *msg, size_t msg_size);
/* The same, shedding what the budget does not hold (cm_cluster_trim) every
 * 1024 lookups: for a pass over the whole cluster, whose chains read more
 * node tables than the budget's quarter (a long explore session's close
 * read 27 MB beyond it). A view's lookups keep them: its other steps read
 * them again. */
cm_status cm_cluster_cells_group_shedding(void *cluster, const int64_t *cells, uint64_t n,
                                          uint32_t *group, char *msg, size_t msg_size);

/* The same, and the open node the cell's sequence leaves the cluster
 * through (CM_NODE_OPEN if it does not: a group, or the world's sink). */
cm_status cm_cluster_cell_end(cm_cluster *c, const int64_t *cell, uint32_t *group,
                              uint32_t *open, char *msg, size_t msg_size);

/* Indexes open node id, whose exit leads to `cell` outside the cluster, by
 * that cell (and in its region's open list, at its end: add a region's in
 * node order), with weight w. */
cm_status cm_cluster_add_escape(cm_cluster *c, uint32_t id, const int64_t *cell, uint64_t w);

/* The two halves of cm_cluster_add_escape: the open list and weight, and
 * the index by target cell. cm_cluster_solve_boxes indexes only the exits
 * that lead outside the boxes it solves (it hands the others to their
 * boxes' joins itself), and the rest if it stops early. */
cm_status cm_cluster_add_open(cm_cluster *c, uint32_t id, const int64_t *cell, uint64_t w);
cm_status cm_cluster_index_escape(cm_cluster *c, uint32_t id, const int64_t *cell);

/* The open nodes whose exits lead into `box` (at most 2^32 cells): a new
 * array of *n of them (ascending by node id) that the caller frees. A
 * cluster without open lists (keep_exits 0) takes them out of its index;
 * with them, they are found in the lists of the regions the index names
 * for the box's bricks (read back if paged out), all that are still open,
 * handed over to the box or not, and leave the lists as they are linked
 * (cm_cluster_take_open). */
cm_status cm_cluster_take_escapes(cm_cluster *c, const cm_box *box, cm_escape **out, uint64_t *n,
                                  char *msg, size_t msg_size);

/* Calls fn for every open node with the target of its exit and its
 * weight (the cells whose sequences leave through it), in ascending node
 * order when the cluster keeps exits (keep_exits), else in the order of
 * the index. Reads paged out open lists back one at a time (and lets each
 * go again). CM_EINVAL once the open nodes are released. */
typedef void (*cm_escape_fn)(void *user, uint32_t node, const int64_t *cell, uint64_t weight);
cm_status cm_cluster_each_escape(cm_cluster *c, cm_escape_fn fn, void *user, char *msg,
                                 size_t msg_size);

/* How many open nodes cm_cluster_each_escape visits, read from no list. */
uint64_t cm_cluster_escape_count(const cm_cluster *c);

/* The target of open node id's exit, from its region's open list (read
 * back if it is paged out) into cell (dim coordinates); *found false when
 * the list does not hold it (a node linked since, or a cluster that keeps
 * no exits). */
cm_status cm_cluster_open_target(cm_cluster *c, uint32_t id, int64_t *cell, bool *found,
                                 char *msg, size_t msg_size);

/* The first place in ascending a[0..n) whose value is not below v: halving
 * without branches (a compare and a conditional move), since the branches
 * of a search over a long open list mispredict. */
static inline uint64_t cm_first_not_below(const uint32_t *a, uint64_t n, uint32_t v)
{
    if (n == 0)
        return 0;
    const uint32_t *base = a;
    while (n > 1) {
        const uint64_t half = n / 2;
        base = base[half] < v ? base + half : base;
        n -= half;
    }
    return (uint64_t)(base - a) + (*base < v);
}

/* Node ids are indexed by blocks of 2^CM_NODE_BLOCK_BITS: the region of each
 * block's first id (c->node_blocks). */
#define CM_NODE_BLOCK_BITS 10

/* The region of node id (O(1): its block's region, then on to the one
 * holding id; regions without nodes share their successor's base). */
static inline uint32_t cm_cluster_node_region(const cm_cluster *c, uint32_t id)
{
    uint32_t k = c->node_blocks[id >> CM_NODE_BLOCK_BITS];
    while (k + 1 < c->nregions && c->node_bases[k + 1] <= id)
        k++;
    return k;
}

/* Node id's record into *out (its region's node table read back through
 * nodes_in if it was paged out). The pointer stays valid until the cluster
 * adds, restores or trims regions (joins and cm_cluster_acquire never evict
 * node tables; cm_cluster_trim does). */
cm_status cm_cluster_node_load(cm_cluster *c, uint32_t id, cm_node **out, char *msg,
                               size_t msg_size);
/* Joins and resolution look nodes up several times per link: the common
 * case (a resident table) is inline, the rest is cm_cluster_node_load. */
static inline cm_status cm_cluster_node(cm_cluster *c, uint32_t id, cm_node **out, char *msg,
                                        size_t msg_size)
{
    if (id < c->nnodes) {
        cm_cluster_region *cr = &c->regions[cm_cluster_node_region(c, id)];
        if (cr->nodes) {
            cr->nodes_used = ++c->clock;
            *out = &cr->nodes[id - cr->node_base];
            return CM_OK;
        }
    }
    return cm_cluster_node_load(c, id, out, msg, msg_size);
}

/* Open nodes and their weights: the cells whose sequences leave the
 * cluster through them (a new node starts with its own tree). Adds w to
 * open node id's weight; takes it out (no longer open) with its weight
 * into *w. nd is id's record (cm_cluster_node). Both mark the node's
 * region open_dirty. */
void cm_cluster_add_open_weight(cm_cluster *c, uint32_t id, cm_node *nd, uint64_t w);
cm_status cm_cluster_take_open(cm_cluster *c, uint32_t id, cm_node *nd, uint64_t *w);

/* Region k's open nodes now (those of its open list still open, the list
 * read back if it is paged out): their exits, weights and target cells
 * into new arrays (*n of them; the caller frees them); the list drops the
 * others. */
cm_status cm_cluster_open_nodes(cm_cluster *c, uint32_t k, uint32_t **local, uint64_t **weight,
                                int64_t **cells, uint64_t *n, char *msg, size_t msg_size);

/* Group and step of node id's cell, following and shortening its chain of
 * links (and settling it, through the cells of its region, when the chain
 * ends on a straddling cycle); *open (may be NULL) is the open node the
 * sequence leaves the cluster through (CM_NODE_OPEN if it does not).
 * CM_ETOOBIG if a step number overflows. */
cm_status cm_cluster_resolve(cm_cluster *c, uint32_t id, uint32_t *group, uint32_t *step,
                             uint32_t *open, char *msg, size_t msg_size);

/* Steps from cell t, in the tree of cycle node q, to the cycle, plus one
 * (t's exit step): reads q's region back if need be. */
cm_status cm_cluster_into_cycle(cm_cluster *c, uint32_t q, uint32_t t, uint64_t *steps,
                                char *msg, size_t msg_size);

/* A new group id (a straddling group) into *g; CM_ETOOBIG past CM_MAX_GROUPS. */
cm_status cm_cluster_new_group(cm_cluster *c, uint32_t *g);

/* Notes cell `local` of region k as a periodic cell of new group g. */
cm_status cm_cluster_note_periodic(cm_cluster *c, uint32_t g, uint32_t k, uint64_t local);

/* Makes region k resident (reading it back if paged out) and marks it used.
 * Under a budget it may evict other regions (never k): pointers into other
 * regions' arrays are invalid after it. */
cm_status cm_cluster_acquire(cm_cluster *c, uint32_t k, char *msg, size_t msg_size);

/* Evicts saved resident regions (in the order cm_cluster_acquire does) until the
 * resident arrays fit c->mem_budget. Does nothing without a pager. */
void cm_cluster_trim(cm_cluster *c);

/* The same at the start of region `joining`'s join, whose cells are not
 * counted (it joins with the budget the cluster had before it). */
void cm_cluster_trim_joining(cm_cluster *c, uint32_t joining);

/* The owner saved everything: regions and node records are clean, the new
 * groups' periodic cells and the changed basin counts are taken. */
void cm_cluster_saved(cm_cluster *c);

/* Summaries of the groups made since cm_cluster_saved (saved_groups + 1 ..
 * ngroups) into a caller array of ngroups - saved_groups entries, from the
 * periodic cells noted for them, which it sorts by group, then box order
 * (the order a file keeps them in): period, anchor, bounds and centre as
 * cm_scm_groups gives them, cells from c->basin, kinds as
 * cm_scm_label_groups gives them (model may be NULL: attractors). No cell
 * is read. CM_EINVAL if a group has no periodic cell. */
cm_status cm_cluster_describe_new(cm_cluster *c, const cm_model *model, cm_group_info *groups,
                                  char *msg, size_t msg_size);

/* Cells in the sink's domain: those whose sequences leave the cluster or the world. */
uint64_t cm_cluster_sink_cells(const cm_cluster *c);

/* Bytes held by the resident regions' cell arrays and exit tables, node
 * tables and open lists that can be paged (open_in): what mem_budget
 * bounds. */
uint64_t cm_cluster_resident_bytes(const cm_cluster *c);

/* The smallest box holding every region (an empty box: none). */
void cm_cluster_bounds(const cm_cluster *c, cm_box *box);

/* Bytes held by the resident arrays, the node tables, the open lists, the
 * indexes and counts. */
uint64_t cm_cluster_bytes(const cm_cluster *c);

/* A flat region over box with no cell computed (group CM_GROUP_NONE,
 * image CM_IMAGE_SINK) and ngroups groups, for cm_flat_copy. */
cm_status cm_flat_alloc(const cm_box *box, uint32_t ngroups, cm_region *out, char *msg,
                        size_t msg_size);
/* Copies the cells of a resolved region r (no node references) inside out's
 * box into out: groups, steps, images as out's indices (exits and cells
 * beyond it as CM_IMAGE_EXIT). */
void cm_flat_copy(const cm_region *r, cm_region *out);

/* The cluster as one region over `box`: resolved group and step of every
 * cell (group CM_GROUP_NONE outside every region), images as box indices
 * (exits and cells beyond the box as CM_IMAGE_EXIT). out->ngroups is the
 * cluster's. Reads only the regions that meet the box. */
cm_status cm_cluster_flatten(cm_cluster *c, const cm_box *box, cm_region *out, char *msg,
                             size_t msg_size);

/* The same, with open[i] (a caller array of the box's cells) the open node
 * through which cell i's sequence leaves the cluster, CM_NODE_OPEN where it
 * does not (a group's cell, the world's sink, no computed cell): what
 * cm_cluster_cell_end gives, found once per node, so that a view's labels
 * need not look up the cells whose sequences leave the view. */
cm_status cm_cluster_flatten_open(cm_cluster *c, const cm_box *box, cm_region *out,
                                  uint32_t *open, char *msg, size_t msg_size);

/* What cm_cluster_flatten_cached keeps between flattens of one cluster:
 * what the nodes of the regions it last met resolve to (13 bytes per node,
 * and 1 MiB for the open nodes a flatten looks up).
 * A node's outcome changes only while its chain ends on an open node, and
 * then only once that node is linked (links never change once set), so a
 * later flatten resolves again only those nodes and the regions it had not
 * met; the result is the same as cm_cluster_flatten_open's. One cache serves
 * one cluster (a cluster of fewer regions than it knows empties it), one
 * flatten at a time. */
typedef struct cm_resolve_cache cm_resolve_cache;

/* An empty cache (NULL when out of memory); _free frees it (NULL: nothing). */
cm_resolve_cache *cm_resolve_cache_new(void);
void cm_resolve_cache_free(cm_resolve_cache *cache);

/* The bytes the cache holds (0 for NULL). */
uint64_t cm_resolve_cache_bytes(const cm_resolve_cache *cache);

/* cm_cluster_flatten_open (open may be NULL) through cache, which then
 * holds the regions that meet box and no others (NULL: every node resolved
 * afresh, as cm_cluster_flatten_open does). On failure the cache is
 * emptied. */
cm_status cm_cluster_flatten_cached(cm_cluster *c, const cm_box *box, cm_resolve_cache *cache,
                                    cm_region *out, uint32_t *open, char *msg,
                                    size_t msg_size);

/* The same, calling progress(user, "cells", fraction of the box's cells
 * read) after each region it reads; nonzero from it cancels (CM_ECANCELED,
 * out freed). */
cm_status cm_cluster_flatten_progress(cm_cluster *c, const cm_box *box, cm_region *out,
                                      cm_progress_fn progress, void *user, char *msg,
                                      size_t msg_size);

#endif
