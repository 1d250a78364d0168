#pragma once
/// @file
/// Parameters of the motion planning service: documented structs with defaults and `validate()`,
/// loaded from YAML (`config/services/motion_planner.yaml`) with tamp::config::FieldReader, which
/// refuses unknown keys and names file:line:column and the field of every bad value.
///
/// Units: metres, radians, seconds, kilograms. "Space metric" is the OMPL state-space distance of
/// the planning group: SE(2) = xy distance + 0.5 m/rad x |yaw difference|; joint space = the
/// Euclidean norm of the joint differences (rad); whole body = SE(2) + 0.5 x joint space.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tamp/core/error.h"

namespace tamp::motion_planner {

/// Which OMPL planner a stage uses.
enum class PlannerKind {
  kLbkpiece,    ///< ompl::geometric::LBKPIECE1: lazy bi-directional KPIECE (Sucan & Kavraki 2009)
  kKpiece,      ///< ompl::geometric::KPIECE1: KPIECE, every motion checked
  kRrtConnect,  ///< ompl::geometric::RRTConnect
};
/// "lbkpiece", "kpiece", "rrtconnect".
std::string_view toString(PlannerKind kind);
std::optional<PlannerKind> plannerKindFromString(std::string_view name);

/// Sampling-based planning (both modes).
struct SamplingParams {
  double validity_resolution{0.02};       ///< longest motion checked by one state, space metric; > 0
  /// How the base moves between two poses: stop and turn (turn in place to the segment's
  /// heading, forwards or backwards, whichever turns less; drive straight; turn in place to the
  /// pose's yaw), as a differential-drive base does; false: a holonomic slide with the yaw
  /// blended in. Every motion check follows it.
  bool base_turn_in_place{true};
  double kpiece_cell_size{0.25};          ///< KPIECE grid cell edge on the base (x, y) projection, m; > 0
  double arm_cell_size{0.3};              ///< KPIECE cell edge on the arm projection, rad; > 0
  double range{0.0};                      ///< longest tree extension, space metric; 0: OMPL's default
  double goal_position_tolerance{0.01};   ///< base goal x, y tolerance, m; > 0
  double goal_orientation_tolerance{0.02};///< base goal yaw and joint goal tolerance, rad; > 0
  double workspace_margin{0.5};           ///< added around the objects' bounds for the base bounds when the world has no explicit workspace, m; >= 0
  PlannerKind lazy_planner{PlannerKind::kLbkpiece};  ///< base group, lazy mode (static geometry)
  PlannerKind full_planner{PlannerKind::kLbkpiece};  ///< base group, full mode (everything known)
  /// Arm and whole-body groups, lazy mode (the paper's KPIECE; the path whose crossings of
  /// movables become sub-tasks). KPIECE1, not LBKPIECE1: LBKPIECE1 needs 0.3-3 s in the arm's
  /// joint space from the folded `stow` configuration where KPIECE1 needs ~15 ms
  /// (docs/benchmarks.md); the lazy mode's laziness is then in the movables, not in the edges.
  PlannerKind arm_planner{PlannerKind::kKpiece};
  /// Arm and whole-body groups, full mode (the path the robot executes, everything known).
  /// RRTConnect: on the arm benchmark (docs/benchmarks.md, session 26) median 10 against 26-28
  /// ms, p95 18-19 against 69-76 ms, the longest 48-52 against 556-565 ms, the same requests
  /// solved, the trajectories 6 % shorter in total; the pick after a drop was KPIECE1's 0.2 s.
  PlannerKind arm_full_planner{PlannerKind::kRrtConnect};
  /// Full mode, a start that touches movable objects only (the robot stopped against one: a
  /// missed grasp, an object dropped against the base; the belief of where it lies is off by
  /// centimetres): the plan leaves by a straight motion that may touch those objects only, to
  /// the nearest state found within this distance (space metric) that touches nothing. Sampled
  /// in `start_escape_attempts` states over growing radii (MoveIt's FixStartStateCollision does
  /// the same). 0: such a start is kStartInCollision. >= 0.
  double start_escape_distance{0.15};
  int start_escape_attempts{400};  ///< >= 1
  /// m, >= 0: the way out goes no deeper than this into the objects the start touches (it is
  /// checked against them this much smaller, as the execution monitor checks a shrunk robot);
  /// only when there is no such way does it leave through them. 0: always through them.
  double start_escape_depth{0.005};
  /// Full mode: the direct motion from the start to a goal state (a straight line in joint
  /// space; for a stop-and-turn base, turn, drive, turn) is checked first and taken when it is
  /// free, before any sampling. Arm motions between nearby configurations usually are. Without
  /// `direct_clearance`, a direct arm motion right after a place swept the fingers past the
  /// object just put down, and the robot was stopped before it (holding_unknown, 3 of 12 runs).
  /// Off here (the library's default, which its tests assume); the shipped service configuration
  /// turns it on with the clearance (config/services/motion_planner.yaml).
  bool direct_first{false};
  /// m, >= 0: with `direct_first`, an arm's direct motion is taken only when the robot grown
  /// sideways by this much sweeps it free (objects are where perception saw them, to within
  /// centimetres); else the motion is sampled. 0: no clearance asked.
  double direct_clearance{0.02};
  /// Full-mode arm paths are checked again as the robot sweeps them: no point of the robot or
  /// the held object moves more than this (m) between two checked states (the simulator stops
  /// before a contact at 1 cm); a segment that touches something is planned again at that
  /// resolution. `validity_resolution` alone moves a fingertip 3-5 cm between checks, and about
  /// 1 in 80 planned paths clipped an object's corner that the robot then stopped before
  /// (tests/contract, tamp_motion_planner_arm_bench). Searching at this resolution throughout
  /// costs 3-4x the planning time; checking the final path costs a few ms. 0: off. >= 0.
  double arm_swept_step{0.0025};
  /// Full-mode base paths keep this much room (m) round every object where there is room for it:
  /// the robot is checked grown sideways by it, except within `base_clearance_near_ends` of the
  /// start and the goal. A base path that hugs an object is lost to the centimetres by which the
  /// object's estimate is off, and the robot is stopped before it (namo_doorway: the way round a
  /// pushed crate). When no such path is found within `base_clearance_time_s` of sampling, the
  /// search goes on without it (its tree stays valid). 0: off. >= 0.
  double base_clearance{0.05};
  double base_clearance_near_ends{0.3};  ///< m, >= 0
  double base_clearance_time_s{0.25};    ///< s, > 0
  /// m, >= 0: a full-mode base path whose start is nearer than this to a movable object goes no
  /// nearer to the movables than its start is (nor than its goal is), within
  /// `base_clearance_near_ends` of the start. A robot stopped before an object stands millimetres
  /// from it; a turn in place there swings a corner towards it, free in the world model by
  /// millimetres and not in the world (namo_room_hidden: stopped three times). 0: off.
  double base_start_margin{0.02};
  /// m, >= 0: base motions of a rigid robot (arm still) first ask a distance grid of the static
  /// objects' footprints with cells this size, and skip the FCL check where the nearest one is
  /// farther than the robot's reach radius (collision/clearance_grid.h). Answers only "free" where
  /// FCL would: paths and decisions are the same, found sooner. 0: off.
  double clearance_grid_resolution{0.05};
};

/// Lazy mode: making the lazy path worth executing (see motion_planner.h). The roadmap of the
/// static free space is cached per planning group and static world (motion_planner.h, "Roadmap
/// cache") and grows across requests; its budgets are counts (deterministic), with a wall-clock
/// safety cap and the request's deadline on top.
struct LazyParams {
  bool optimize{true};              ///< effort-aware roadmap search + shortcutting of the lazy path
  int roadmap_samples{600};         ///< uniform samples of the static free space in a new roadmap; >= 0
  int roadmap_bridge_samples{200};  ///< bridge-test samples (narrow passages) in a new base-group roadmap; >= 0
  double roadmap_bridge_distance{0.8};  ///< typical distance of a bridge's two colliding ends (space metric); > 0
  int roadmap_neighbors{12};        ///< k of the k-nearest-neighbour connections; >= 2
  double path_node_spacing{0.5};    ///< a lazy KPIECE path is cut into roadmap nodes this far apart (space metric); > 0
  int roadmap_max_evaluations{1000}; ///< edge evaluations per roadmap search before it gives up; >= 1
  /// Roadmap-first search: it gives up (lazy KPIECE runs) after finding this many edges newly
  /// statically invalid -- a roadmap that does not connect start and goal shows that way; >= 1
  int roadmap_max_new_invalid{30};
  int roadmap_growth_samples{100};  ///< uniform samples added when a request falls back to lazy KPIECE; >= 0
  int roadmap_max_nodes{4000};      ///< no uniform samples are added beyond this many nodes; >= 1
  /// Requests' starts and goals become roadmap nodes; beyond this many the least recently used
  /// are removed (down to half), so a long mission does not grow the roadmap without bound; >= 2
  int roadmap_max_request_nodes{400};
  /// Base group: when the roadmap's best path crosses movables, this many samples are added just
  /// outside each of them (once per object pose) and the roadmap is searched again: gaps between
  /// objects and walls that uniform samples miss; >= 0 (0: off)
  int object_ring_samples{24};
  int roadmap_cache_entries{4};     ///< roadmaps kept per planner (static world x group x held object), LRU; 0: none kept
  /// Base group: search the cached roadmap first (when it existed before the request) and run
  /// lazy KPIECE only when it cannot connect start and goal; false (and other groups, and a new
  /// roadmap): lazy KPIECE first, its path then seeds the roadmap.
  bool roadmap_first{true};
  double optimize_budget_s{0.5};    ///< wall-clock cap of one roadmap search (safety net; the request's deadline also applies); > 0
  int shortcut_attempts{150};       ///< effort-aware shortcut attempts; >= 0
  double contact_resolution{0.01};  ///< dense re-check of the final path against movables, space metric; > 0
  double swept_spacing{0.05};       ///< spacing of the reported swept states, space metric; > 0
};

/// The path cost that decides which movable objects a lazy path may cross:
///   cost [s] = path length / speed + sum over crossed objects o of scale x effort(o).
/// effort(o) is the execution time of moving o out of the way: pick + place (the effort
/// estimator's default time models, tamp::effort_model, with o's mass) + driving
/// `transfer_distance` to a placement and back; objects the gripper cannot hold (not graspable)
/// cost `non_graspable_factor` times as much (pushing, two-handed handling, ...).
struct CostParams {
  double base_speed{0.5};             ///< m/s: base path length -> time; > 0
  double arm_speed{1.0};              ///< rad/s: arm path length -> time; > 0
  double approach_distance{0.10};     ///< m, pick and place approach; >= 0
  double retreat_distance{0.10};      ///< m, pick and place retreat; >= 0
  double transfer_distance{1.5};      ///< m, one way, to where the object is put; >= 0
  double non_graspable_factor{3.0};   ///< >= 1
};

/// Full mode on the base (and whole body with a known base goal): the proof of `no path`.
/// A grid over the base bounds whose cells keep the robot's inscribed disc free somewhere inside
/// them over-approximates the free space; when start and goal fall in different 8-connected
/// components of those cells, no path exists (a proof, not a timeout). Cells are refined from
/// `cell_size` down to `min_cell_size`, in turns interleaved with the planner's time slices:
/// a first turn before sampling (full mode), then after each slice one of `time_share` times
/// the slice, each going on from where the last one stopped.
struct ProofParams {
  bool enabled{true};
  double cell_size{0.1};       ///< m, first (coarsest) grid; > 0
  double min_cell_size{0.02};  ///< m, finest grid; in (0, cell_size]
  int max_cells{4000000};      ///< grids with more cells are skipped; >= 1
  /// Then (x, y, yaw) cells for the base box (it cannot turn where it stands): yaw cells per
  /// turn (0 or 1: off), their xy edge (m, > 0), and how many it may keep before it gives up
  /// (>= 1; about 50 bytes each).
  int yaw_cells{64};
  double oriented_cell_size{0.025};
  int oriented_max_cells{500000};
  /// Then (full mode) that many finer (x, y, yaw) grids, each with half the xy edge and twice the
  /// yaw cells (>= 0): a passage a few centimetres too narrow for the base to turn in is proven. A
  /// finer grid runs only where the last one found start and goal connected with few enough
  /// cells that eight times as many (about what the finer one tests) stay within
  /// oriented_max_cells; elsewhere (large open regions) it would only run into that cap.
  int oriented_refinements{2};
  double first_turn_s{0.02};   ///< s, the turn before sampling (both modes); >= 0
  double time_share{1.0};      ///< proof time per second of sampling; >= 0
  /// The same for a lazy request (movables free), in [0, time_share]. The sampler answers nearly
  /// all of them (none of 239 was proven impossible in a namo_moghaddam_07 mission, whose lazy
  /// paths spent 40 % of their time in the proof), but a quarter of time_share showed no gain
  /// there (docs/evaluation.md, thirty-second session): shipped equal to it.
  double lazy_time_share{1.0};
};

/// Trapezoidal time parameterization (stop at every waypoint; see trajectory_timing.h).
struct TimingParams {
  double base_linear_speed{0.5};   ///< m/s; > 0
  double base_linear_accel{0.5};   ///< m/s^2; > 0
  double base_angular_speed{1.0};  ///< rad/s; > 0
  double base_angular_accel{1.5};  ///< rad/s^2; > 0
  double arm_accel{2.0};           ///< rad/s^2 for every arm joint; > 0 (URDF gives speeds only)
  double arm_speed_scale{1.0};     ///< fraction of the URDF joint speed used; in (0, 1]
  double sample_period{0.05};      ///< s between trajectory points (plus every phase change); > 0
};

/// Placement sampling (findEffectStates).
struct PlacementParams {
  int max_attempts{400};            ///< object poses tried per request; >= 1
  double support_margin{0.01};      ///< m the footprint keeps inside the region's polygon; >= 0
  double base_distance_min{0.45};   ///< m, base-to-object distances tried for reachability; > 0
  double base_distance_max{0.85};   ///< m; >= base_distance_min
  int base_poses_per_placement{12}; ///< base poses tried per placement; >= 1
  double planar_reach{1.0};         ///< m, planar robots (no arm): object within this of a free base pose; > 0
  double tool_clearance{0.02};      ///< m above the object's top face for the tool reachability test; >= 0
};

/// Grasp generation.
struct GraspParams {
  double approach_distance{0.10};   ///< m, pre-grasp offset along the approach axis; > 0
  double retreat_distance{0.10};    ///< m, lift after closing (world +z); >= 0
  double finger_margin{0.005};      ///< m, opening beyond the object's width (each side); >= 0
  double side_height_fraction{0.5}; ///< side grasps at this fraction of the object's height; in [0, 1]
  int cylinder_yaw_samples{8};      ///< yaws tried around a cylinder's axis; >= 1
  double base_distance_min{0.45};   ///< m, base poses tried when none is given; > 0
  double base_distance_max{0.85};   ///< m; >= base_distance_min
  int base_poses{16};               ///< base poses tried per grasp when none is given; >= 1
};

struct MotionPlannerParams {
  std::uint32_t seed{42};  ///< OMPL's global seed (see seedRandomness()) and our own samplers
  SamplingParams sampling;
  LazyParams lazy;
  CostParams cost;
  ProofParams proof;
  TimingParams timing;
  PlacementParams placement;
  GraspParams grasp;

  /// Ok, or kInvalidArgument listing every bad field by its dotted name ("lazy.roadmap_samples").
  Status validate() const;
};

/// Loads and validates a YAML file; every key is optional (the defaults above), unknown keys are
/// errors except the top-level `foreign_sections` (read by someone else, e.g. the DDS node's
/// `node` section). Errors name file:line:column and the field.
Result<MotionPlannerParams> loadMotionPlannerParams(const std::filesystem::path& file,
                                                    const std::vector<std::string>& foreign_sections = {});
/// Same from text; `name` is used as the file name in messages.
Result<MotionPlannerParams> parseMotionPlannerParams(const std::string& yaml_text, const std::string& name,
                                                     const std::vector<std::string>& foreign_sections = {});

}  // namespace tamp::motion_planner
