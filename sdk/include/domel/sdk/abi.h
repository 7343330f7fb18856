/* SPDX-License-Identifier: MIT
 *
 * domel SDK — the C ABI between the domel runtime and its plugins (ABI 2).
 *
 * This header is the single source of truth for the binary boundary. It is
 * plain C so a plugin may be built with any compiler and standard library:
 * no STL, Eigen, nlohmann or exceptions cross it. Rules (see docs/sdk-guide.md):
 *
 *  - A plugin library exports exactly one symbol, domel_plugin_entry_v2, that
 *    returns a static domel_library_v2 describing every model it provides.
 *    Each model descriptor (domel_model_v2) carries the common members (kind,
 *    name, version, schema, create/destroy) and a pointer to the callback
 *    table of its FAMILY: contact stages (normal, damping, tangential,
 *    rolling, twisting) -> domel_contact_family_v2, insertion ->
 *    domel_insertion_family_v2, controller -> domel_controller_family_v1,
 *    fluid coupler -> domel_fluid_coupler_family_v1. Adding a family adds a
 *    table; it never changes an existing one (the OBS module pattern).
 *  - Every struct begins with its own size (struct_size). Minor ABI versions
 *    only append fields; the host zero-fills what an older plugin lacks. A
 *    required callback that is missing (or lies beyond a table's struct_size)
 *    is refused at load time, naming the callback.
 *  - ABI 1 plugins (domel_plugin_entry_v1) are refused with a message naming
 *    both versions; so is a plugin of a future major (entry_v3, or
 *    abi_major 3 in the library description). docs/sdk-guide.md, "Versions".
 *  - Errors come back as a domel_status plus a message written into a
 *    caller-owned buffer; the host adds the context (model, library, scenario
 *    location). Host services (domel_host_v2) let a plugin log and report
 *    errors under its own name.
 *  - Kernels work on batches: the host hands over N contacts as
 *    structure-of-arrays pointers; there is never one call per contact.
 *
 * Conventions for contact batches: index c in [0, n). "i" is the particle
 * the batch is written for, "j" is its partner (another particle, or a wall).
 * The unit normal n points from j to i, so the normal force on i is +F_n n.
 * All quantities are SI.
 */
#ifndef DOMEL_SDK_ABI_H
#define DOMEL_SDK_ABI_H

#include <stddef.h>
#include <stdint.h>

#define DOMEL_ABI_MAJOR 2
#define DOMEL_ABI_MINOR 6

#if defined(_WIN32)
#define DOMEL_EXPORT __declspec(dllexport)
#else
#define DOMEL_EXPORT __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Result of every fallible ABI call. */
typedef enum domel_status {
  DOMEL_OK = 0,
  DOMEL_ERR_PARAMETER = 1, /**< parameters rejected (create) */
  DOMEL_ERR_RUNTIME = 2,   /**< a callback could not do its work */
  DOMEL_ERR_CAPACITY = 3   /**< output buffer too small; retry with more room */
} domel_status;

/** What a model is. Contact kinds fill one slot of the contact pipeline,
 *  evaluated in this fixed order for each batch:
 *  normal -> damping -> (host sums F_n) -> tangential -> rolling -> twisting.
 *  The family of each kind (which table `family` points to) is given here. */
typedef enum domel_kind {
  DOMEL_KIND_NORMAL = 1,          /**< contact family: elastic normal force, stiffness, contact radius */
  DOMEL_KIND_DAMPING = 2,         /**< contact family: normal dashpot force */
  DOMEL_KIND_TANGENTIAL = 3,      /**< contact family: tangential (friction) force */
  DOMEL_KIND_ROLLING = 4,         /**< contact family: rolling-resistance torque */
  DOMEL_KIND_TWISTING = 5,        /**< contact family: twisting-resistance torque */
  DOMEL_KIND_INSERTION = 10,      /**< insertion family: creates particle positions and radii */
  DOMEL_KIND_FLUID_COUPLER = 20,  /**< fluid_coupler family: per-particle fluid forces */
  DOMEL_KIND_CONTROLLER = 30      /**< controller family: forces from the cell averages of coupled levels */
} domel_kind;

/* ------------------------------------------------------------------------ */
/* Host services                                                             */
/* ------------------------------------------------------------------------ */

/** Services the host offers ONE model instance: `create` receives a pointer
 *  that stays valid until `destroy` returns. `context` identifies the
 *  instance, so the host prefixes every message with the model's kind and
 *  name, its library and the scenario location that created it. */
typedef struct domel_host_v2 {
  uint32_t struct_size;
  uint32_t abi_minor;
  void* context;
  /** level: 0 debug, 1 info, 2 warning, 3 error. Thread-safe. */
  void (*log)(void* context, int level, const char* utf8_message);
  /** Report an error with its context: the host logs it at error level,
   *  prefixed as for log, and keeps it as the instance's last error. A
   *  callback that then returns a failure status with an empty message
   *  buffer is reported with this text. Thread-safe. */
  void (*error)(void* context, domel_status code, const char* utf8_message);
  /** ABI 2.6: nonzero once this process was asked to stop (SIGINT, SIGTERM)
   *  more than a second ago and the macro step in progress has not ended by
   *  itself (it would end with a checkpoint). A callback that may run for
   *  long (many insertion attempts, many fluid steps in one exchange) asks
   *  every so often and, when told to stop, fails (DOMEL_ERR_RUNTIME) with a
   *  message saying how far it got: the host ends the run as interrupted
   *  without finishing the step (the last checkpoint stands). Cheap (a clock
   *  read); thread-safe. Absent (beyond struct_size) in hosts older than 2.6:
   *  read it as 0. */
  int (*stop_requested)(void* context);
} domel_host_v2;

/* ------------------------------------------------------------------------ */
/* Contact family                                                            */
/* ------------------------------------------------------------------------ */

/** Material-pair constants: one parameter set per pair of materials (and per
 *  material/wall pair). A batch says per contact which set applies, see
 *  domel_contact_batch_v2::pair and ::pair_of. */
typedef struct domel_pair_v2 {
  uint32_t struct_size;
  uint32_t is_wall;      /**< nonzero: j is a wall (R* = R_i, m* = m_i, mass_j = 0) */
  double youngs_eff;     /**< E*: 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j  [Pa] */
  double shear_eff;      /**< G*: 1/G* = 2(2-nu_i)(1+nu_i)/E_i + (same for j)  [Pa] */
  double restitution;    /**< normal coefficient of restitution e  [-] */
  double friction;       /**< sliding friction coefficient mu  [-] */
  double coarse_grain;   /**< coarse-grain ratio alpha of the subdomain  [-] */
  /** coefficient of rolling friction mu_r of this pair [-], valid when
   *  has_rolling_friction is nonzero (the torque cap is mu_r R* F_n;
   *  mu_r = tan(theta_c) for a critical rolling angle theta_c). Zero-filled,
   *  i.e. not given for this pair: the rolling model's own parameter applies.
   *  The built-in rolling models and the epsd example honour it. */
  double rolling_friction;
  uint32_t has_rolling_friction;
  uint32_t reserved;     /**< 0 */
} domel_pair_v2;

/** A batch of n contacts, structure of arrays. Arrays marked [in] are
 *  filled by the host; [stage] arrays are written by the named stage and
 *  read by later stages; [out] arrays are this stage's result. */
typedef struct domel_contact_batch_v2 {
  uint32_t struct_size;
  uint32_t n;
  double dt;                  /**< time step of the subdomain  [s] */
  /** Which material-pair parameter set applies to each contact:
   *  pair != NULL: every contact of the batch uses *pair (the common case,
   *  read once per batch); pair_of may then be NULL.
   *  pair == NULL: contact c uses *pair_of[c]; the host groups contacts of
   *  one pair next to each other. The C++ layer (plugin.hpp) splits such a
   *  batch into runs of one pair, so a C++ compute() always sees pair set. */
  const domel_pair_v2* pair;
  const domel_pair_v2* const* pair_of;

  /* [in] geometry and kinematics */
  const double* overlap;      /**< delta_n > 0  [m] */
  const double *nx, *ny, *nz; /**< unit normal, from j to i */
  const double* r_eff;        /**< R*  [m] */
  const double* m_eff;        /**< m*  [kg] */
  const double* radius_i;     /**< R_i [m] */
  const double* radius_j;     /**< R_j [m] (0 for a wall) */
  const double* mass_i;       /**< m_i [kg] */
  const double* mass_j;       /**< m_j [kg] (0 for a wall) */
  const double* vn;           /**< normal relative speed, > 0 when approaching  [m/s] */
  const double *vtx, *vty, *vtz; /**< tangential relative velocity of i's contact point w.r.t. j's  [m/s] */
  const double *wx, *wy, *wz; /**< relative angular velocity omega_i - omega_j  [rad/s] */

  /* [stage: normal] */
  double* fn_elastic;     /**< elastic normal force on i along n  [N] */
  double* kn;             /**< secant normal stiffness F_el/delta  [N/m] */
  double* kn_tangent;     /**< tangent normal stiffness dF_el/d delta  [N/m] */
  double* contact_radius; /**< radius a of the contact disk  [m] */
  /* [stage: damping] */
  double* fn_damping;     /**< dashpot normal force on i along n (positive repulsive)  [N] */
  double* eta_n;          /**< normal dashpot coefficient  [N s/m] */
  /* [host, after damping] */
  double* fn;             /**< total normal force on i along n  [N] */
  /* [out: tangential] tangential force on i (j receives the opposite)  [N] */
  double *ftx, *fty, *ftz;
  /* [out: rolling, twisting] torque couple on i, ADDED to (j receives the opposite)  [N m] */
  double *tqx, *tqy, *tqz;
  /* [out: rolling] the rolling spring and dashpot constants of each contact,
   * k_theta [N m/rad] and n_theta [N m s/rad], for the host's rotational
   * time-step check (docs/physics.md §3.6). Zeroed by the host before the
   * rolling stage; a model without a spring or dashpot leaves them 0. */
  double* rolling_stiffness;
  double* rolling_damping;

  /* this stage's history: element k of contact c is history[c*history_stride + k].
   * Zero when a contact first forms; the host keeps it across neighbour-list
   * rebuilds and particle re-ordering, and zeroes it when the contact opens. */
  double* history;
  uint32_t history_stride;
} domel_contact_batch_v2;

/* Thread safety: the host may call `contact` of ONE instance from several
 * threads at once, each with its own batch. A contact kernel must therefore
 * not modify its instance; per-contact state belongs in history. */
typedef domel_status (*domel_contact_fn)(void* instance, domel_contact_batch_v2* batch, char* err,
                                         size_t err_capacity);

/** domel_contact_family_v2::flags (ABI 2.1): the stage never reads the
 *  batch's mass_i and mass_j, so the host may leave them unfilled (stale)
 *  when no stage of the pipeline reads them: two stores per contact less. */
#define DOMEL_CONTACT_IGNORES_MASSES 1u

/** Callbacks of the contact family (kinds normal ... twisting). */
typedef struct domel_contact_family_v2 {
  uint32_t struct_size;
  uint32_t history_slots;   /**< doubles of per-contact history this stage needs */
  domel_contact_fn contact; /**< required */
  /* ABI 2.1 */
  uint32_t flags;           /**< DOMEL_CONTACT_* bits; 0 (and a 2.0 table): every batch input is filled */
} domel_contact_family_v2;

/* ------------------------------------------------------------------------ */
/* Insertion family                                                          */
/* ------------------------------------------------------------------------ */

/** An insertion region. shape 1: box [lo, hi]. shape 2: cylinder with the
 *  given axis (0 x, 1 y, 2 z) through `center`, radius `radius`, extending
 *  from lo[axis] to hi[axis]. (Unchanged since ABI 1.) */
typedef struct domel_region_v1 {
  uint32_t struct_size;
  uint32_t shape;
  double lo[3];
  double hi[3];
  double center[3];
  double radius;
  uint32_t axis;
} domel_region_v1;

typedef struct domel_insert_request_v1 {
  uint32_t struct_size;
  domel_region_v1 region;
  uint64_t seed;              /**< per-inserter seed; same seed => same particles */
  double length_scale;        /**< coarse-grain ratio alpha: radii are multiplied by it */
  size_t n_existing;          /**< particles already present, to be avoided */
  const double *ex_x, *ex_y, *ex_z, *ex_r;
  /* ABI 2.3 */
  size_t max_count;           /**< the most particles the host accepts from this call (the scenario's
                                   run.max_particles); 0: no limit. A model that would place more refuses
                                   before it allocates them: a region or a diameter in the wrong unit
                                   otherwise fills the memory (domel::sdk::Inserted does it) */
} domel_insert_request_v1;

typedef struct domel_insert_output_v1 {
  uint32_t struct_size;
  size_t capacity;            /**< room in x, y, z, r */
  size_t count;               /**< written; on DOMEL_ERR_CAPACITY: the count needed */
  double *x, *y, *z, *r;
  /* ABI 2.4 */
  uint32_t *component;        /**< NULL, or room for `capacity` entries: the host asks which component of a
                                   mixture ("distribution": {"type": "mixture", ...}) each particle is drawn
                                   from (its index in "components"); a model that cannot say leaves the
                                   host's fill (UINT32_MAX) and the host refuses the mixture.
                                   domel::sdk::SizeDistribution::draw and Inserted::push do it */
} domel_insert_output_v1;

typedef domel_status (*domel_insert_fn)(void* instance, const domel_insert_request_v1* request,
                                        domel_insert_output_v1* output, char* err, size_t err_capacity);

/** Callbacks of the insertion family. */
typedef struct domel_insertion_family_v2 {
  uint32_t struct_size;
  uint32_t reserved;        /**< 0 */
  domel_insert_fn insert;   /**< required */
} domel_insertion_family_v2;

/* ------------------------------------------------------------------------ */
/* Shared views for the controller and fluid_coupler families                */
/* ------------------------------------------------------------------------ */

/** Read-only cell averages of one level on its hexahedral grid
 *  (docs/physics.md §5). Cell (ix, iy, iz) has index ix + nx (iy + ny iz).
 *  Per-cell arrays have n_cells entries; a cell with no particle has
 *  count 0, mass 0 and zero velocities (its min and max too). */
typedef struct domel_cell_grid_v1 {
  uint32_t struct_size;
  uint32_t nx, ny, nz;        /**< cells per axis */
  double origin[3];           /**< lower corner of cell (0,0,0)  [m] */
  double spacing[3];          /**< cell edge lengths  [m] */
  size_t n_cells;             /**< nx ny nz */
  const uint32_t* count;      /**< particles whose centre lies in the cell */
  const double* volume_fraction; /**< solid volume fraction phi  [-] */
  const double* mass;         /**< particle mass in the cell  [kg] */
  const double *ux, *uy, *uz; /**< mass-weighted mean velocity  [m/s] */
  /** smallest and largest particle velocity per component in the cell [m/s] */
  const double *u_min_x, *u_min_y, *u_min_z;
  const double *u_max_x, *u_max_y, *u_max_z;
  /** stress tensor, 6 per cell in the order xx, yy, zz, xy, xz, yz, kinetic
   *  plus contact part, compression negative  [Pa] */
  const double* stress;
} domel_cell_grid_v1;

/** Particle state of one level. Positions, velocities and the rest are
 *  [in]; fx, fy, fz are [out]: the external force on each particle, ADDED to
 *  (the host zeroes them before the call and applies them as body forces
 *  until the next call). */
typedef struct domel_particles_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  size_t n;
  const uint64_t* id;         /**< stable particle id */
  const double *x, *y, *z;    /**< position  [m] */
  const double *vx, *vy, *vz; /**< velocity  [m/s] */
  const double* mass;         /**< [kg] */
  const double* radius;       /**< [m] */
  const uint32_t* cell;       /**< cell index in the level's grid; UINT32_MAX outside it */
  double *fx, *fy, *fz;       /**< [out] external force  [N] */
} domel_particles_v1;

/** One resolution level (a subdomain) as a controller or coupler sees it. */
typedef struct domel_level_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  const char* name;           /**< subdomain name */
  double coarse_grain;        /**< coarse-grain ratio alpha  [-] */
  const domel_cell_grid_v1* cells;
  domel_particles_v1* particles;
} domel_level_v1;

/* ------------------------------------------------------------------------ */
/* Controller family                                                          */
/* ------------------------------------------------------------------------ */

/** Where a model writes its state for a checkpoint (ABI 2.3): the host's
 *  sink. write() appends n bytes to the model's state and may be called any
 *  number of times; it returns DOMEL_OK, or an error status the model passes
 *  back. The bytes are the model's own format: the host stores them as they
 *  are, with the model's name and version, and hands them back to
 *  load_state of an instance created with the same parameters. */
typedef struct domel_state_sink_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  void* host;                 /**< the host's, passed back to write */
  domel_status (*write)(void* host, const void* data, size_t n);
} domel_state_sink_v1;

/* A model that keeps state between calls (an integral term, a fluid field)
 * provides both, so that a run stopped at a checkpoint and restarted goes on
 * exactly as the uninterrupted run (docs/checkpoint.md). save_state writes
 * everything the model's next call depends on; load_state, called on a
 * fresh instance before its first call, restores it or refuses (a wrong
 * size, a version it cannot read) with a message. A model without them
 * cannot be checkpointed: the host refuses run.checkpoint_interval and
 * --restart for a scenario that uses it, naming the model. A model without
 * state provides both too, saving nothing. */
typedef domel_status (*domel_save_state_fn)(void* instance, const domel_state_sink_v1* sink, char* err,
                                            size_t err_capacity);
typedef domel_status (*domel_load_state_fn)(void* instance, const void* data, size_t n, char* err,
                                            size_t err_capacity);

/** One control interval of a coupling between levels. levels[0] is the
 *  level the coupling is declared on (e.g. the fine one), levels[1] its
 *  partner (e.g. the coarse one); level_count is 2 for a coupling of two
 *  levels. A controller may write forces to the particles of any level. */
typedef struct domel_control_step_v1 {
  uint32_t struct_size;
  uint32_t level_count;
  double time;                /**< simulated time at the end of the interval  [s] */
  double interval;            /**< length of the control interval  [s] */
  domel_level_v1* const* levels;
} domel_control_step_v1;

/** One level of a coupling as its controller is set up (ABI 2.5): what
 *  the host derived from the scenario for that level. */
typedef struct domel_control_level_setup_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  const char* name;           /**< subdomain name */
  double coarse_grain;        /**< coarse-grain ratio alpha  [-] */
  double time_step;           /**< the level's time step  [s] */
  uint64_t steps_per_interval; /**< the level's steps in one control interval */
} domel_control_level_setup_v1;

/** What a controller is set up for (ABI 2.5), once, before the run: the
 *  derived values of its coupling, so that a model computes its defaults
 *  (a gain of 1/N for N steps per interval) and checks its parameters (cell
 *  indices) from them rather than from parameters the host would have to
 *  invent. levels[] are in the order of the control steps' levels. The
 *  inflow cells are the grid's cells touching a face through which material
 *  enters levels[0] (the scenario's inflow_faces), each with its inward
 *  normal (components -1, 0 or 1; a corner cell of two inflow faces has two
 *  non-zero components), in increasing cell index. */
typedef struct domel_control_setup_v1 {
  uint32_t struct_size;
  uint32_t level_count;
  double interval;            /**< length of the control interval  [s] */
  const domel_control_level_setup_v1* levels;
  uint32_t nx, ny, nz;        /**< the cells of the levels' common grid */
  size_t n_cells;             /**< nx ny nz */
  double origin[3];           /**< lower corner of cell (0,0,0)  [m] */
  double spacing[3];          /**< cell edge lengths  [m] */
  size_t n_inflow_cells;
  const uint32_t* inflow_cell;      /**< n_inflow_cells cell indices */
  const int32_t* inflow_direction;  /**< 3 per inflow cell: the inward normal */
} domel_control_setup_v1;

/* Called once after create and before any other call (load_state and
 * control included): the model resolves its defaults from the setup and may
 * refuse it (DOMEL_ERR_PARAMETER with a message: a cell index beyond the
 * grid), which the host reports at the controller's block before the run. */
typedef domel_status (*domel_control_setup_fn)(void* instance, const domel_control_setup_v1* setup, char* err,
                                               size_t err_capacity);

/* Called once per control interval, from one thread at a time: a controller
 * may keep state (an integral term) in its instance. */
typedef domel_status (*domel_control_fn)(void* instance, domel_control_step_v1* step, char* err,
                                         size_t err_capacity);

/** Callbacks of the controller family. */
typedef struct domel_controller_family_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  domel_control_fn control;   /**< required */
  /* ABI 2.3; optional: NULL, or beyond struct_size, means not provided */
  domel_save_state_fn save_state; /**< its state for a checkpoint (with load_state) */
  domel_load_state_fn load_state;
  /* ABI 2.5; optional */
  domel_control_setup_fn setup;   /**< the coupling's derived values, before the run */
} domel_controller_family_v1;

/* ------------------------------------------------------------------------ */
/* Fluid-coupler family                                                       */
/* ------------------------------------------------------------------------ */

/** The linearised drag of one level (ABI 2.2): the host refreshes
 *  F_i = beta_i (u_i - v_i) with the particle's CURRENT velocity v_i at every
 *  time step until the next exchange, so the drag stays stable however short
 *  the particle's relaxation time m_i/beta_i is against the coupling
 *  interval. The host zeroes the arrays before each exchange; a particle the
 *  coupler leaves at beta 0 feels no refreshed drag. */
typedef struct domel_fluid_drag_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  size_t n;                   /**< = the level's particles->n */
  double* beta;               /**< [out] drag coefficient of the particle (a parcel: all it stands for)  [kg/s] */
  double *ux, *uy, *uz;       /**< [out] fluid velocity the particle sees  [m/s] */
} domel_fluid_drag_v1;

/** One coupling exchange: the particle data of the levels that share the
 *  fluid go to the fluid solver; the per-particle fluid force comes back
 *  in two parts: particles->fx, fy, fz (added to; held constant until the
 *  next exchange: pressure gradient and any force the coupler does not
 *  linearise) and, when the host offers it, the linearised drag of
 *  domel_fluid_drag_v1 (refreshed every step). `cells` of a level is NULL,
 *  and so is its particles->cell: a coupler keeps its own grid. */
typedef struct domel_fluid_exchange_v1 {
  uint32_t struct_size;
  uint32_t reserved;          /**< 0 */
  double time;                /**< simulated time  [s] */
  double interval;            /**< coupling interval: the time between exchanges  [s] */
  domel_level_v1* level;      /**< levels[0] */
  /* ABI 2.2 */
  double gravity[3];          /**< the scenario's gravity  [m/s^2] */
  uint32_t level_count;       /**< levels sharing this fluid (>= 1) */
  uint32_t host_flags;        /**< DOMEL_FLUID_HOST_*: what the host offers in this call */
  domel_level_v1* const* levels;
  /** per level, when DOMEL_FLUID_HOST_DRAG: the linearised drag [out] */
  domel_fluid_drag_v1* const* drag;
  /** per level, when DOMEL_FLUID_HOST_MEAN_VELOCITY: 3 n values x0, y0, z0,
   *  x1, ...: each particle's velocity averaged over the interval that ends
   *  now (since its insertion for a newer particle; its current velocity on
   *  the first exchange)  [m/s]. With it a coupler gives the fluid exactly
   *  the momentum the refreshed drag gave the particles. */
  const double* const* v_mean;
} domel_fluid_exchange_v1;

#define DOMEL_FLUID_HOST_DRAG 1u          /**< drag[] is there: the host refreshes beta (u - v) every step */
#define DOMEL_FLUID_HOST_MEAN_VELOCITY 2u /**< v_mean[] is there */

/* Called once per coupling interval, from one thread at a time. */
typedef domel_status (*domel_fluid_exchange_fn)(void* instance, domel_fluid_exchange_v1* exchange, char* err,
                                                size_t err_capacity);

/** The coupler's own fields for output (ABI 2.2), cell-centred on a uniform
 *  grid: cell (ix, iy, iz) has index ix + nx (iy + ny iz), as
 *  domel_cell_grid_v1. The coupler owns the memory; it stays valid until the
 *  next call into the instance. The host writes them as VTK image data.
 *  The grid is the fluid's domain: the host also calls this once before the
 *  run and refuses a scenario whose particles start outside it. */
typedef struct domel_fluid_fields_v1 {
  uint32_t struct_size;
  uint32_t field_count;       /**< [out] */
  uint32_t nx, ny, nz;        /**< [out] cells per axis */
  double origin[3];           /**< [out] lower corner of cell (0,0,0)  [m] */
  double spacing[3];          /**< [out] cell edge lengths  [m] */
  const char* const* names;   /**< [out] e.g. "void_fraction", "pressure", "velocity" */
  const char* const* units;   /**< [out] e.g. "1", "Pa", "m/s" */
  const uint32_t* components; /**< [out] 1 (scalar) or 3 (vector, interleaved x, y, z per cell) */
  const double* const* data;  /**< [out] field k: nx ny nz components[k] values */
} domel_fluid_fields_v1;

/** What bounds the coupling (ABI 2.2): the host refuses to run a coupling
 *  interval longer than max_interval, naming `limit`, and records the rest.
 *  Called once right after create (the limit of the initial state: inlet
 *  velocities, grid), when the host refuses the scenario before anything
 *  runs, and after every exchange, when it stops the run. */
typedef struct domel_fluid_limits_v1 {
  uint32_t struct_size;
  uint32_t solver_iterations; /**< [out] iterations of the last solve (0: none) */
  double max_interval;        /**< [out] longest stable coupling interval at the current state  [s]; 0: no limit */
  const char* limit;          /**< [out] which limit that is, e.g. "advective CFL |u| dt/dx <= 0.5" (static text) */
  double solver_residual;     /**< [out] relative residual of the last solve (0: none)  [-] */
  /* ABI 2.6: the last exchange's momentum books (a coupler fills them only
   * when struct_size reaches them) */
  uint32_t has_books;         /**< [out] 1: the two below are filled */
  double momentum_residual;   /**< [out] the force put on the fluid plus the drag given to the particles, against
                                   the sum of the drags' magnitudes, per axis (the largest), at the exchange's end
                                   state: 0 but for round-off when the exchange conserves momentum  [-] */
  double wall_shear[3];       /**< [out] the force of the no-slip walls on the fluid at the end of the exchange
                                   (the rest of the pressure drop besides the particles' drag)  [N] */
} domel_fluid_limits_v1;

typedef domel_status (*domel_fluid_fields_fn)(void* instance, domel_fluid_fields_v1* out, char* err,
                                              size_t err_capacity);
typedef domel_status (*domel_fluid_limits_fn)(void* instance, domel_fluid_limits_v1* out, char* err,
                                              size_t err_capacity);

/** Callbacks of the fluid_coupler family. */
typedef struct domel_fluid_coupler_family_v1 {
  uint32_t struct_size;
  uint32_t reserved;                /**< 0 */
  domel_fluid_exchange_fn exchange; /**< required */
  /* ABI 2.2; optional: NULL, or beyond struct_size, means not provided */
  domel_fluid_fields_fn fields;     /**< the coupler's fields, for output */
  domel_fluid_limits_fn limits;     /**< its stability limit, checked after every exchange */
  /* ABI 2.3; optional */
  domel_save_state_fn save_state;   /**< its state (fields, solver warm start) for a checkpoint */
  domel_load_state_fn load_state;
} domel_fluid_coupler_family_v1;

/* ------------------------------------------------------------------------ */
/* Model and library descriptors                                             */
/* ------------------------------------------------------------------------ */

typedef domel_status (*domel_create_fn)(const char* params_json, const domel_host_v2* host,
                                        void** out_instance, char* err, size_t err_capacity);
typedef void (*domel_destroy_fn)(void* instance);

/** One model. `create`, `destroy`, `family` and the required callbacks of
 *  its family's table are required. */
typedef struct domel_model_v2 {
  uint32_t struct_size;
  uint32_t kind;                  /**< domel_kind; selects the type `family` points to */
  const char* name;               /**< scenario keyword, lowercase snake_case, unique per kind */
  const char* version;            /**< model version, "MAJOR.MINOR.PATCH" */
  const char* summary;            /**< one line for `domel plugins` */
  const char* params_schema_json; /**< JSON Schema of its parameters, "x-unit" on each number */
  domel_create_fn create;
  domel_destroy_fn destroy;
  /** The family's table: domel_contact_family_v2, domel_insertion_family_v2,
   *  domel_controller_family_v1 or domel_fluid_coupler_family_v1, by kind.
   *  Each begins with its struct_size. */
  const void* family;
} domel_model_v2;

/** What domel_plugin_entry_v2 returns: a static description of the library. */
typedef struct domel_library_v2 {
  uint32_t struct_size;
  uint32_t abi_major;          /**< DOMEL_ABI_MAJOR the library was built with */
  uint32_t abi_minor;          /**< DOMEL_ABI_MINOR the library was built with */
  const char* name;            /**< library name, e.g. "domel_contact_std" */
  const char* version;         /**< library version */
  uint32_t model_count;
  const domel_model_v2* const* models;
} domel_library_v2;

/** The one exported entry symbol. */
#define DOMEL_ENTRY_SYMBOL "domel_plugin_entry_v2"
typedef const domel_library_v2* (*domel_entry_fn)(void);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* DOMEL_SDK_ABI_H */
