/* src/commands.h - the subcommands of `cellmap`. Each returns the exit
 * status: 0 success, 1 failure, 2 bad usage. */
#ifndef CM_SRC_COMMANDS_H
#define CM_SRC_COMMANDS_H

int cmd_models(int argc, char **argv);
int cmd_solve(int argc, char **argv);
/* solve on MPI ranks (lib/ranks.h; the program cellmap-mpi) */
struct solve_ranks;
int cmd_solve_on(int argc, char **argv, struct solve_ranks *ranks);
int cmd_orbit(int argc, char **argv);
int cmd_equilibria(int argc, char **argv);
int cmd_periodic(int argc, char **argv);
int cmd_exponents(int argc, char **argv);
int cmd_fixed_points(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_export(int argc, char **argv);
int cmd_measure(int argc, char **argv);
/* `export` inside an explore session: cellmap export's words (argv[1] the
 * session's file) over the session's own open database and cluster, which
 * is not opened a second time. */
struct session;
int cmd_export_in(int argc, char **argv, struct session *open);
int cmd_explore(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_lyapunov(int argc, char **argv);
int cmd_simulate(int argc, char **argv);
int cmd_continue(int argc, char **argv);
int cmd_amplitude(int argc, char **argv);
int cmd_escape(int argc, char **argv);
int cmd_stability(int argc, char **argv);
int cmd_horseshoe(int argc, char **argv);
int cmd_partition(int argc, char **argv);
int cmd_bifurcation(int argc, char **argv);
int cmd_sweep(int argc, char **argv);
/* In the program cellmap-serve only (src/cmd_serve.c). */
int cmd_serve(int argc, char **argv);

#endif
