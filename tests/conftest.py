"""Test configuration: seeded (derandomized) hypothesis runs, the repository's path."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

# "seeded" (the default): what CI runs. "thorough": twenty times the examples, for a release or a
# change to the planner (HYPOTHESIS_PROFILE=thorough); tests that set max_examples keep theirs.
settings.register_profile(
    "seeded",
    derandomize=True,
    max_examples=50,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
settings.register_profile("thorough", settings.get_profile("seeded"), max_examples=1000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "seeded"))

#: The repository (a clone of it): the tests read nothing outside it (tests/test_clone.py).
REPO = Path(__file__).resolve().parent.parent

#: End-to-end tests, marked ``slow``: the docs build, the examples, installs, live runs over a broker,
#: demos and simulations on the command line, runs under load, other processes, the optimal
#: method's accuracy set, the online campaign, and the property tests over many random solves.
#: ``pytest -m "not slow" -n auto`` is the fast set a developer runs after a change (about two
#: minutes on two cores); CI runs everything. A test file may mark itself (``pytestmark``).
SLOW_FILES = {
    "test_accuracy.py",
    "test_campaign.py",
    "test_determinism.py",
    "test_docs.py",
    "test_docs_broker.py",
    "test_examples.py",
    "test_readme.py",
    "test_install.py",
    "test_live.py",
    "test_live_broker.py",
    "test_live_faults.py",
    "test_live_link.py",
    "test_live_restart.py",
    "test_live_security.py",
    "test_simulate_cli.py",
    "test_store.py",
    "test_commit_processes.py",
}
SLOW_TESTS = {
    "test_graph_planner.py::test_the_planner_equals_a_grid_oracle_on_random_trees_and_graphs_with_loops",
    "test_online.py::test_campaign_scenarios_that_failed_reach_their_goals_safely",
    "test_online.py::test_a_new_goal_mid_run_is_reached_with_no_violation",
    "test_online.py::test_a_lagging_drive_never_moves_a_frontier_back",
    "test_online.py::test_seed_12_campaign_scenarios_that_braked_hard_keep_the_braking_invariant",
    "test_online.py::test_single_stops_on_random_tracks_cost_at_most_their_bound",
    "test_coordination.py::test_every_methods_plan_for_execution_obeys_the_braking_rule",
    "test_classes.py::test_the_class_lower_bound_holds_in_both_classes",
    "test_classes.py::test_the_converged_references_are_what_a_converged_solve_gives",
    "test_optimal.py::test_lower_bound_optimal_exact_order_and_verification",
    "test_optimal.py::test_fatrop_solves_the_five_phase_reordering_on_one_leg",
    "test_optimal.py::test_backup_solvers_reach_fatrops_optimum",
    "test_schedule.py::test_the_closed_form_verifier_agrees_with_the_sampled_second_opinion",
    "test_coordination.py::test_the_rule_binds_the_optimal_swap_two_centimetres_more_is_refused",
    "test_cli.py::test_schedule_writes_verified_csv_and_plots_that_check_passes",
    "test_cli.py::test_demo_runs_a_built_in_scenario_end_to_end",
    "test_online.py::test_an_undisturbed_run_executes_its_plan_within_one_percent_and_never_brakes",
    "test_plot_api.py::test_a_renderer_of_0_6_warns_and_returns_the_png_of_its_plot",
    "test_coordination.py::test_verify_refuses_a_plan_that_breaks_the_rule_naming_when_and_where",
    "test_online.py::test_a_stop_costs_about_its_own_length",
    "test_online.py::test_a_single_stop_at_any_moment_costs_at_most_its_bound",
    "test_online.py::test_seed_12_campaign_scenarios_that_deadlocked_reach_their_goals_safely",
    "test_optimal.py::test_swaps_are_at_most_half_of_exact_and_stay_in_the_class",
    # junctions of 4 to 8 legs: their pictures, schedules, exports and commands
    "test_pictures.py::test_every_leg_is_in_the_frame_to_scale",
    "test_pictures.py::test_the_layout_draws_k_k_plus_1_vertices_and_2k_k_minus_1_edges",
    "test_pictures.py::test_arcs_from_one_valley_never_cross",
    "test_pictures.py::test_the_drawn_route_passes_the_routes_vertices_of_g_k_in_order",
    "test_pictures.py::test_a_point_inside_an_edge_is_drawn_its_share_of_the_way_along",
    "test_pictures.py::test_the_schedules_path_retracts_onto_the_routes_edges",
    "test_pictures.py::test_the_titles_name_the_class_and_the_rule_that_chose_the_route",
    "test_schedule.py::test_every_method_verifies_on_k_legs",
    "test_schedule.py::test_optimal_is_no_slower_than_exact_on_k_legs",
    "test_schedule.py::test_exact_schedules_of_random_star_queries_verify",
    "test_schedule.py::test_the_verifier_rejects_a_vehicle_on_a_leg_the_track_lacks",
    "test_export.py::test_csv_legs_are_one_based_up_to_k_and_xy_follow_the_angles",
    "test_cli.py::test_demo_refuses_an_unknown_scenario",
    "test_dialects.py::test_check_rejects_a_leg_the_crossing_lacks",
    "test_dialects.py::test_table_dialects_on_a_crossing",
    "test_vda5050.py::test_export_vda5050_on_k_legs_validates_and_places_nodes_by_angle",
    "test_vda5050.py::test_export_vda5050_on_a_crossing_with_optimal",
    "test_scenario.py::test_builtin_scenario_refuses_an_unknown_name",
    "test_scenario.py::test_the_scenario_refuses_nine_legs",
    "test_scenario.py::test_the_scenario_refuses_a_separation_longer_than_legs_naming_them",
    "test_scenario.py::test_random_scenarios_on_k_legs_plan_and_verify",
    "test_scenario.py::test_random_track_refuses_a_leg_count_out_of_range",
    "test_scenario.py::test_random_three_leg_tracks_are_ygraphs_as_before",
    "test_classes.py::test_optimal_fastest_on_a_crossing_takes_the_faster_of_two_classes",
    "test_online.py::test_the_executor_on_a_crossing_checks_legs_by_count",
}
#: Tests parametrized over the number of legs (a ``legs`` argument) of which only some cases are
#: slow: test -> the slow values of ``legs``. A test of a property every junction has runs on the
#: Y in the fast set and on the stars of 4 to 8 legs end to end (their pictures, commands, files).
SLOW_LEGS = {
    "test_pictures.py::test_the_first_frame_shows_the_start_and_the_last_the_goal": {4, 5, 8},
    "test_pictures.py::test_frame_positions_are_the_schedules_positions": {4, 5, 8},
    "test_pictures.py::test_render_configuration_of_a_route_and_of_a_schedule": {4, 8},
    "test_pictures.py::test_plot_writes_configuration_png": {4, 8},
    "test_pictures.py::test_animate_writes_the_gif": {4, 8},
    "test_schedule.py::test_verifier_catches_the_other_homotopy_class": {4},
    "test_cli.py::test_plan_prints_the_route": {4},
    "test_cli.py::test_plan_json_summary": {4},
    "test_scenario.py::test_example_file_is_the_built_in_scenario_and_ships_as_package_data": {4},
}


def pytest_configure(config) -> None:
    """Give the run its own store of compiled NLPs and vehicle places (in the process that starts the others).

    The optimal method keeps the NLPs it builds in a disk store (``$TRAJGEN_CACHE_DIR``, else the
    user's cache folder). The run points it at a new temporary folder, which every worker and
    every process the tests start inherit: nothing of the user's cache is read, and each shape is
    built once for the whole run. It is deleted when the run ends.
    """
    if hasattr(config, "workerinput"):
        return
    import tempfile

    store = tempfile.TemporaryDirectory(prefix="trajgen-test-nlp-")
    config._trajgen_store = store  # kept alive until pytest_unconfigure
    os.environ["TRAJGEN_CACHE_DIR"] = store.name
    # the vehicles' remembered places (trajgen.live.memory) too: nothing of the user's home is read
    os.environ["TRAJGEN_STATE_DIR"] = os.path.join(store.name, "state")


def pytest_unconfigure(config) -> None:
    """Delete the run's store of compiled NLPs (after the workers and the runs they started)."""
    store = getattr(config, "_trajgen_store", None)
    if store is not None:
        store.cleanup()


def pytest_collection_modifyitems(config, items) -> None:
    """Mark the end-to-end tests ``slow``.

    :data:`SLOW_FILES`, :data:`SLOW_TESTS`, the cases of :data:`SLOW_LEGS`, and the accuracy set.
    """
    slow = pytest.mark.slow
    for item in items:
        name = item.path.name
        test = f"{name}::{getattr(item, 'originalname', item.name)}"
        legs = item.callspec.params.get("legs") if hasattr(item, "callspec") else None
        if (
            name in SLOW_FILES
            or test in SLOW_TESTS
            or legs in SLOW_LEGS.get(test, ())
            or item.get_closest_marker("accuracy")
        ):
            item.add_marker(slow)
