/* SPDX-License-Identifier: MIT
 *
 * domel SDK — the C ABI between the domel runtime and its plugins.
 *
 * This header is the single source of truth for the binary boundary. It is
 * plain C so a plugin may be built with any compiler and standard library:
 * no STL, Eigen, nlohmann or exceptions cross it. Rules (see docs/sdk-guide.md):
 *
 *  - A plugin library exports exactly one symbol, domel_plugin_entry_v1, that
 *    returns a static domel_library_v1 describing every model it provides.
 *    A future incompatible ABI exports domel_plugin_entry_v2 instead.
 *  - Every struct begins with its own size (struct_size). Minor ABI versions
 *    only append fields; the host zero-fills what an older plugin lacks.
 *  - Errors come back as a domel_status plus a message written into a
 *    caller-owned buffer.
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

#define DOMEL_ABI_MAJOR 1
#define DOMEL_ABI_MINOR 1

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
  DOMEL_ERR_RUNTIME = 2,   /**< a kernel could not do its work */
  DOMEL_ERR_CAPACITY = 3   /**< output buffer too small; retry with more room */
} domel_status;

/** What a model is. Contact kinds fill one slot of the contact pipeline,
 *  evaluated in this fixed order for each batch:
 *  normal -> damping -> (host sums F_n) -> tangential -> rolling -> twisting. */
typedef enum domel_kind {
  DOMEL_KIND_NORMAL = 1,     /**< elastic normal force, stiffness, contact radius */
  DOMEL_KIND_DAMPING = 2,    /**< normal dashpot force */
  DOMEL_KIND_TANGENTIAL = 3, /**< tangential (friction) force */
  DOMEL_KIND_ROLLING = 4,    /**< rolling-resistance torque */
  DOMEL_KIND_TWISTING = 5,   /**< twisting-resistance torque */
  DOMEL_KIND_INSERTION = 10, /**< creates particle positions and radii */
  DOMEL_KIND_FLUID = 20,     /**< reserved: fluid coupler */
  DOMEL_KIND_CONTROLLER = 30 /**< reserved: coupling controller */
} domel_kind;

/** Services the host offers a plugin instance. */
typedef struct domel_host_v1 {
  uint32_t struct_size;
  uint32_t abi_minor;
  void* context;
  /** level: 0 debug, 1 info, 2 warning, 3 error. Thread-safe. */
  void (*log)(void* context, int level, const char* utf8_message);
} domel_host_v1;

/** Material-pair constants, the same for every contact of a batch. */
typedef struct domel_pair_v1 {
  uint32_t struct_size;
  uint32_t is_wall;      /**< nonzero: j is a wall (R* = R_i, m* = m_i) */
  double youngs_eff;     /**< E*: 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j  [Pa] */
  double shear_eff;      /**< G*: 1/G* = 2(2-nu_i)(1+nu_i)/E_i + (same for j)  [Pa] */
  double restitution;    /**< normal coefficient of restitution e  [-] */
  double friction;       /**< sliding friction coefficient mu  [-] */
  double coarse_grain;   /**< coarse-grain ratio alpha of the subdomain  [-] */
} domel_pair_v1;

/** A batch of n contacts, structure of arrays. Arrays marked [in] are
 *  filled by the host; [stage] arrays are written by the named stage and
 *  read by later stages; [out] arrays are this stage's result. */
typedef struct domel_contact_batch_v1 {
  uint32_t struct_size;
  uint32_t n;
  double dt;                  /**< time step of the subdomain  [s] */
  const domel_pair_v1* pair;  /**< material-pair constants */

  /* [in] geometry and kinematics */
  const double* overlap;      /**< delta_n > 0  [m] */
  const double *nx, *ny, *nz; /**< unit normal, from j to i */
  const double* r_eff;        /**< R*  [m] */
  const double* m_eff;        /**< m*  [kg] */
  const double* radius_i;     /**< R_i [m] */
  const double* radius_j;     /**< R_j [m] (0 for a wall) */
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

  /* this stage's history: element k of contact c is history[c*history_stride + k].
   * Zero when a contact first forms; the host keeps it across neighbour-list
   * rebuilds and particle re-ordering, and zeroes it when the contact opens. */
  double* history;
  uint32_t history_stride;

  /* ---- appended in ABI 1.1 ---- */
  /* [out: rolling] the rolling spring and dashpot constants of each contact,
   * k_theta [N m/rad] and n_theta [N m s/rad], for the host's rotational
   * time-step check (docs/physics.md §3.6). Zeroed by the host before the
   * rolling stage; a model without a spring or dashpot leaves them 0. */
  double* rolling_stiffness;
  double* rolling_damping;
} domel_contact_batch_v1;

/** An insertion region. shape 1: box [lo, hi]. shape 2: cylinder with the
 *  given axis (0 x, 1 y, 2 z) through `center`, radius `radius`, extending
 *  from lo[axis] to hi[axis]. */
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
} domel_insert_request_v1;

typedef struct domel_insert_output_v1 {
  uint32_t struct_size;
  size_t capacity;            /**< room in x, y, z, r */
  size_t count;               /**< written; on DOMEL_ERR_CAPACITY: the count needed */
  double *x, *y, *z, *r;
} domel_insert_output_v1;

typedef domel_status (*domel_create_fn)(const char* params_json, const domel_host_v1* host,
                                        void** out_instance, char* err, size_t err_capacity);
typedef void (*domel_destroy_fn)(void* instance);
/* Thread safety (ABI 1.1): the host may call `contact` of ONE instance from
 * several threads at once, each with its own batch. A contact kernel must
 * therefore not modify its instance; per-contact state belongs in history. */
typedef domel_status (*domel_contact_fn)(void* instance, domel_contact_batch_v1* batch,
                                         char* err, size_t err_capacity);
typedef domel_status (*domel_insert_fn)(void* instance, const domel_insert_request_v1* request,
                                        domel_insert_output_v1* output, char* err,
                                        size_t err_capacity);

/** One model. `create`, `destroy` and the callback of its kind are required. */
typedef struct domel_model_v1 {
  uint32_t struct_size;
  uint32_t kind;                  /**< domel_kind */
  const char* name;               /**< scenario keyword, lowercase snake_case, unique per kind */
  const char* version;            /**< model version, "MAJOR.MINOR.PATCH" */
  const char* summary;            /**< one line for `domel plugins` */
  const char* params_schema_json; /**< JSON Schema of its parameters, "x-unit" on each number */
  uint32_t history_slots;         /**< doubles of per-contact history (contact kinds) */
  uint32_t flags;                 /**< reserved, 0 */
  domel_create_fn create;
  domel_destroy_fn destroy;
  domel_contact_fn contact;       /**< contact kinds */
  domel_insert_fn insert;         /**< DOMEL_KIND_INSERTION */
} domel_model_v1;

/** What domel_plugin_entry_v1 returns: a static description of the library. */
typedef struct domel_library_v1 {
  uint32_t struct_size;
  uint32_t abi_major;          /**< DOMEL_ABI_MAJOR the library was built with */
  uint32_t abi_minor;          /**< DOMEL_ABI_MINOR the library was built with */
  const char* name;            /**< library name, e.g. "domel_contact_std" */
  const char* version;         /**< library version */
  uint32_t model_count;
  const domel_model_v1* const* models;
} domel_library_v1;

/** The one exported entry symbol. */
#define DOMEL_ENTRY_SYMBOL "domel_plugin_entry_v1"
typedef const domel_library_v1* (*domel_entry_fn)(void);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* DOMEL_SDK_ABI_H */
