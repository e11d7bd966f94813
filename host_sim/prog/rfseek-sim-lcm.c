/* rfseek-sim-lcm.c - the simulator with the controller in a separate process.
 *
 *   rfseek-sim-lcm SCENARIO [--lcm URL] [--can IFACE] [--seed N] [--timeout-ms N] [--max-time S]
 *                  [--log FILE]
 *
 * Runs the scenario like rfseek-sim, but the controller is rfseekd --clock-lcm in another
 * process: poses and RSSI go out on LCM, one RFS_CLOCK per control period, and the
 * simulated motor controller takes the wheel commands from CAN (SocketCAN with --can,
 * else the LCM fallback channel RFS_CAN_FALLBACK). Prints summary.json to stdout, checked
 * at exit like every program's (lx_err_close_stdout); --log writes rfseek-sim's log.tsv,
 * renamed into place when the run ends.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hs_ctrl_lcm.h"
#include "lx_err.h"
#include "hs_scenario.h"
#include "hs_sim.h"

static const char usage_text[] =
    "usage: rfseek-sim-lcm SCENARIO [--lcm URL] [--can IFACE] [--seed N] [--timeout-ms N] [--max-time S]\n"
    "                      [--log FILE]\n"
    "Simulate SCENARIO with the controller running as a separate process (rfseekd --clock-lcm).\n"
    "  --lcm URL        LCM provider shared with rfseekd (default: LCM's default)\n"
    "  --can IFACE      take wheel commands from SocketCAN (default: LCM channel RFS_CAN_FALLBACK)\n"
    "  --seed N         run seed (default: the scenario's)\n"
    "  --timeout-ms N   wait this long for the controller's answer to a step (default 5000)\n"
    "  --max-time S     stop after S simulated seconds (overrides the scenario's stop time)\n"
    "  --log FILE       write the decisions as rfseek-sim's log.tsv (its flags, the estimate)\n"
    "  -h, --help       this text\n";

static const char PROG[] = "rfseek-sim-lcm"; /* the prefix of its error lines (lx_err_print) */

/* One run, its decisions (log.tsv) written beside log_path (NULL: none) and renamed into
 * place when the run ends, as the summary is printed: 0, or -1 with err. */
static int run_logged(const hs_sim_env_t *env, uint64_t seed, hs_ctrl_t *ctrl, const char *log_path,
                      hs_sim_result_t *res, char *err, size_t errlen)
{
    hs_sim_io_t io;
    memset(&io, 0, sizeof io);
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", log_path ? log_path : "", (long)getpid());
    if (log_path && !(io.log = fopen(tmp, "w"))) {
        snprintf(err, errlen, "%s: cannot write: %s", log_path, strerror(errno));
        return -1;
    }
    int rc = hs_sim_run(env, seed, ctrl, &io, res, err, errlen);
    if (io.log) {
        bool lost = fclose(io.log) != 0;
        if (rc == 0 && (lost || rename(tmp, log_path) != 0)) {
            snprintf(err, errlen, "%s: %s", log_path, lost ? "write failed" : strerror(errno));
            rc = -1;
        }
        if (rc != 0) {
            remove(tmp);
        }
    }
    return rc;
}

static int sim_lcm_main(int argc, char **argv)
{
    const char *scn = NULL;
    hs_ctrl_lcm_cfg_t cfg = hs_ctrl_lcm_cfg_default();
    cfg.prog = PROG;
    long long seed = -1;
    double max_time = 0;
    const char *log_path = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        char *end = NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            return 0;
        } else if (a[0] != '-' && !scn) {
            scn = a;
        } else if (a[0] != '-') {
            lx_err_print(PROG, "unexpected argument '%s' (one SCENARIO only)", a);
            return 2;
        } else if (strcmp(a, "--lcm") != 0 && strcmp(a, "--can") != 0 && strcmp(a, "--seed") != 0 &&
                   strcmp(a, "--max-time") != 0 && strcmp(a, "--timeout-ms") != 0 && strcmp(a, "--log") != 0) {
            lx_err_print(PROG, "unknown option '%s' (see --help)", a);
            return 2;
        } else if (!v) {
            lx_err_print(PROG, "missing value for %s (see --help)", a);
            return 2;
        } else if (*v == '\0') { /* "" for --lcm would be liblcm's default provider */
            lx_err_print(PROG, "empty value for %s (see --help)", a);
            return 2;
        } else if (strcmp(a, "--lcm") == 0) {
            cfg.lcm_url = v, i++;
        } else if (strcmp(a, "--can") == 0) {
            cfg.can_iface = v, i++;
        } else if (strcmp(a, "--log") == 0) {
            if (lx_err_path_opt(PROG, a, v) != 0) {
                return 2;
            }
            log_path = v, i++;
        } else if (strcmp(a, "--seed") == 0) {
            errno = 0;
            seed = strtoll(v, &end, 10);
            if (errno || *end || seed < 0) {
                lx_err_print(PROG, "--seed: '%s' is not a non-negative integer", v);
                return 2;
            }
            i++;
        } else if (strcmp(a, "--max-time") == 0) {
            max_time = strtod(v, &end);
            if (*end || !(max_time > 0 && max_time <= 86400)) {
                lx_err_print(PROG, "--max-time: '%s' is not seconds in (0, 86400]", v);
                return 2;
            }
            i++;
        } else { /* --timeout-ms */
            long t = strtol(v, &end, 10);
            if (*end || t < 1 || t > 600000) {
                lx_err_print(PROG, "--timeout-ms: '%s' is not in 1..600000", v);
                return 2;
            }
            cfg.reply_timeout_ms = (int)t;
            i++;
        }
    }
    if (!scn) {
        lx_err_print(PROG, "a SCENARIO file is required (see --help)");
        return 2;
    }
    if (log_path && (lx_err_same_file(PROG, scn, log_path) != 0 || lx_err_check_dest(PROG, log_path) != 0)) {
        return 1;
    }
    char err[512];
    hs_scenario_t sc;
    if (hs_scenario_load(scn, &sc, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    if (max_time > 0) {
        sc.stop_time_s = max_time;
    }
    hs_sim_env_t env;
    memset(&env, 0, sizeof env);
    if (hs_sim_env_open(&env, &sc, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    hs_ctrl_t ctrl;
    if (hs_ctrl_lcm_open(&ctrl, &cfg, err, sizeof err) != 0) {
        lx_err_print(PROG, "%s", err);
        hs_sim_env_close(&env);
        return 1;
    }
    if (err[0]) { /* liblcm's warning, as one line (hs_ctrl_lcm.h) */
        lx_err_print(PROG, "%s", err);
    }
    hs_sim_result_t res;
    int rc = run_logged(&env, seed >= 0 ? (uint64_t)seed : sc.seed, &ctrl, log_path, &res, err, sizeof err);
    uint32_t timeouts = hs_ctrl_lcm_timeouts(&ctrl);
    hs_ctrl_close(&ctrl);
    if (rc != 0) {
        lx_err_print(PROG, "%s", err);
        hs_sim_env_close(&env);
        return 1;
    }
    hs_sim_write_summary(stdout, &env, &res);
    if (timeouts) {
        fprintf(stderr, "rfseek-sim-lcm: %u control steps got no answer in time\n", timeouts);
    }
    hs_sim_env_close(&env);
    return timeouts ? 1 : 0;
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(PROG, sim_lcm_main(argc, argv));
}
