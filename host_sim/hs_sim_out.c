/* hs_sim_out.c - a run's result as written (hs_sim.h): summary.json and the rows of a
 * batch's runs.tsv. */
#include "hs_sim.h"

#include <math.h>

static void json_num(FILE *f, const char *key, double v, bool last)
{
    if (isfinite(v)) {
        fprintf(f, "  \"%s\": %.3f%s\n", key, v, last ? "" : ",");
    } else {
        fprintf(f, "  \"%s\": null%s\n", key, last ? "" : ",");
    }
}

void hs_sim_write_summary(FILE *f, const hs_sim_env_t *e, const hs_sim_result_t *r)
{
    fprintf(f, "{\n");
    fprintf(f, "  \"scenario\": \"%s\",\n", e->sc.path);
    fprintf(f, "  \"seed\": %llu,\n", (unsigned long long)r->seed);
    fprintf(f, "  \"model\": \"%s\",\n", e->sc.model);
    fprintf(f, "  \"strategy\": \"%s\",\n", e->sc.strategy);
    fprintf(f, "  \"target\": \"%s\",\n", e->sc.target);
    fprintf(f, "  \"map\": \"%s\",\n", e->sc.map_path);
    fprintf(f, "  \"start\": [%.3f, %.3f],\n", e->sc.start_x, e->sc.start_y);
    fprintf(f, "  \"sources\": [");
    for (unsigned s = 0; s < e->sc.nsources; s++) {
        fprintf(f, "%s[%.3f, %.3f]", s ? ", " : "", e->sc.src[s].x, e->sc.src[s].y);
    }
    fprintf(f, "],\n");
    fprintf(f, "  \"start_theta_rad\": %.4f,\n", e->sc.start_theta);
    if (e->placement > 0) { // a drawn placement (hs_place.h)
        fprintf(f, "  \"placement\": %llu,\n  \"placement_seed\": %llu,\n",
                (unsigned long long)e->placement, (unsigned long long)e->placement_seed);
    } else {
        fprintf(f, "  \"placement\": null,\n  \"placement_seed\": null,\n");
    }
    fprintf(f, "  \"reached\": %s,\n", r->reached ? "true" : "false");
    fprintf(f, "  \"end\": \"%s\",\n", r->end);
    json_num(f, "sim_time_s", r->sim_time_s, false);
    json_num(f, "distance_travelled_m", r->distance_travelled_m, false);
    json_num(f, "shortest_path_m", r->shortest_path_m, false);
    json_num(f, "shortest_to_stop_m", r->shortest_to_stop_m, false);
    json_num(f, "final_distance_m", r->final_distance_m, false);
    json_num(f, "final_x_m", r->final_x, false);
    json_num(f, "final_y_m", r->final_y, false);
    fprintf(f, "  \"iterations\": %u,\n", r->iterations);
    fprintf(f, "  \"model_updates\": %u,\n", r->model_updates);
    fprintf(f, "  \"greedy\": %u,\n", r->greedy);
    fprintf(f, "  \"epsilon\": %u,\n", r->epsilon);
    fprintf(f, "  \"packets_sent\": %llu,\n", (unsigned long long)r->packets_sent);
    fprintf(f, "  \"packets_received\": %llu,\n", (unsigned long long)r->packets_received);
    fprintf(f, "  \"motor_timeouts\": %u,\n", r->motor_timeouts);
    fprintf(f, "  \"goal_timeouts\": %u,\n", r->goal_timeouts);
    fprintf(f, "  \"goal_blocked\": %u,\n", r->goal_blocked);
    fprintf(f, "  \"slow_decisions\": %u,\n", r->slow_decisions);
    fprintf(f, "  \"plan_wait_max\": %u,\n", r->plan_wait_max);
    fprintf(f, "  \"decisions_over_100ms\": %u,\n", r->decisions_over_100ms);
    json_num(f, "decision_wait_max_s", r->decision_wait_max_s, false);
    json_num(f, "decision_wait_mean_s",
             r->iterations > 0u ? r->decision_wait_sum_s / r->iterations : NAN, false);
    json_num(f, "turn_time_s", r->turn_time_s, false);
    fprintf(f, "  \"wall_contacts\": %ld,\n", r->wall_contacts);
    // The path-loss model's final estimate (null for other models).
    json_num(f, "est_src_x_m", r->est_valid ? r->est_x : NAN, false);
    json_num(f, "est_src_y_m", r->est_valid ? r->est_y : NAN, false);
    json_num(f, "est_n", r->est_valid ? r->est_n : NAN, false);
    json_num(f, "est_w_db", r->est_valid ? r->est_w_db : NAN, false);
    json_num(f, "est_p0", r->est_valid ? r->est_p0 : NAN, false);
    json_num(f, "est_area_m2", r->est_valid ? r->est_area_m2 : NAN, false);
    json_num(f, "est_error_m", r->est_valid ? r->est_error_m : NAN, false);
    // The belief at the end and how long the robot had stood (docs/RESULTS.md, the failure
    // taxonomy of "Generalisation: random placements").
    json_num(f, "belief_x_m", r->belief_x, false);
    json_num(f, "belief_y_m", r->belief_y, false);
    json_num(f, "belief_error_m", r->belief_error_m, false);
    json_num(f, "still_s", r->still_s, !r->bridge);
    if (r->bridge) {
        // Bridging (hs_bridge.h): the true f's best point, the settle point, the estimate.
        json_num(f, "best_x_m", r->best_x, false);
        json_num(f, "best_y_m", r->best_y, false);
        json_num(f, "best_f_db", r->best_f_db, false);
        json_num(f, "settle_f_db", r->settle_f_db, false);
        json_num(f, "settle_error_m", r->settle_error_m, false);
        json_num(f, "settle_travel_m", r->settle_travel_m, false);
        json_num(f, "far_f_db", r->far_f_db, false);
        json_num(f, "pred_x_m", r->pred_valid ? r->pred_x : NAN, false);
        json_num(f, "pred_y_m", r->pred_valid ? r->pred_y : NAN, false);
        json_num(f, "pred_f_db", r->pred_valid ? r->pred_f_db : NAN, false);
        json_num(f, "pred_sigma_db", r->pred_valid ? r->pred_sigma_db : NAN, false);
        json_num(f, "pred_area_m2", r->pred_valid ? r->pred_area_m2 : NAN, !r->pred_valid);
        if (r->pred_valid) {
            // Each node's fit, [x_m, y_m, p0_dbm, n, w_db, rms_db], beside "sources".
            fprintf(f, "  \"pred_sources\": [");
            for (unsigned k = 0; k < 2; k++) {
                fprintf(f, "%s[", k ? ", " : "");
                for (unsigned i = 0; i < 6; i++) {
                    double v = r->pred_src[k][i];
                    if (isfinite(v)) {
                        fprintf(f, "%s%.3f", i ? ", " : "", v);
                    } else {
                        fprintf(f, "%snull", i ? ", " : "");
                    }
                }
                fprintf(f, "]");
            }
            fprintf(f, "]\n");
        }
    }
    fprintf(f, "}\n");
}

void hs_sim_table_header(FILE *f, bool placed, bool bridge)
{
    fprintf(f, "%sseed\treached\tend\tsim_time_s\tdistance_travelled_m\tshortest_path_m\t"
               "shortest_to_stop_m\tfinal_distance_m\tfinal_x_m\tfinal_y_m\titerations\t"
               "model_updates\tgreedy\tepsilon\tpackets_sent\tpackets_received\t"
               "goal_timeouts\tgoal_blocked\tturn_time_s\twall_contacts%s%s\n",
            placed ? "placement\t" : "",
            placed ? "\tstart_x_m\tstart_y_m\tstart_theta_rad\tsource_x_m\tsource_y_m"
                     "\test_error_m\tbelief_error_m\tstill_s" : "",
            bridge ? "\t" HS_SIM_BRIDGE_COLUMNS : "");
}

/// %.3f, or "nan" for a value that does not exist (no goal).
static void tsv_num(FILE *f, double v)
{
    if (isfinite(v)) {
        fprintf(f, "\t%.3f", v);
    } else {
        fprintf(f, "\tnan");
    }
}

void hs_sim_table_row(FILE *f, const hs_sim_result_t *r, bool placed)
{
    if (placed) {
        fprintf(f, "%llu\t", (unsigned long long)r->placement);
    }
    fprintf(f, "%llu\t%d\t%s", (unsigned long long)r->seed, r->reached ? 1 : 0, r->end);
    tsv_num(f, r->sim_time_s);
    tsv_num(f, r->distance_travelled_m);
    tsv_num(f, r->shortest_path_m);
    tsv_num(f, r->shortest_to_stop_m);
    tsv_num(f, r->final_distance_m);
    tsv_num(f, r->final_x);
    tsv_num(f, r->final_y);
    fprintf(f, "\t%u\t%u\t%u\t%u\t%llu\t%llu\t%u\t%u", r->iterations, r->model_updates,
            r->greedy, r->epsilon, (unsigned long long)r->packets_sent,
            (unsigned long long)r->packets_received, r->goal_timeouts, r->goal_blocked);
    tsv_num(f, r->turn_time_s);
    fprintf(f, "\t%ld", r->wall_contacts);
    if (placed) {
        fprintf(f, "\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f", r->start_x, r->start_y, r->start_theta,
                r->source_x, r->source_y);
        tsv_num(f, r->est_valid ? r->est_error_m : NAN);
        tsv_num(f, r->belief_error_m);
        tsv_num(f, r->still_s);
    }
    if (r->bridge) {
        const double v[] = {r->best_x, r->best_y, r->best_f_db, r->settle_f_db,
                            r->settle_error_m, r->settle_travel_m,
                            r->pred_valid ? r->pred_x : NAN, r->pred_valid ? r->pred_y : NAN,
                            r->pred_valid ? r->pred_f_db : NAN,
                            r->pred_valid ? r->pred_sigma_db : NAN,
                            r->pred_valid ? r->pred_area_m2 : NAN, r->far_f_db};
        for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
            tsv_num(f, v[i]);
        }
    }
    fputc('\n', f);
}

