/* SPDX-License-Identifier: MIT
 *
 * A valid fluid coupler built as ABI 2.1 knew the family: the library says
 * abi_minor 1, its table ends after `exchange` (no fields, no limits), and
 * it reads only exchange->level (2.1 had one level per exchange and no
 * linearised drag). "abi21_push" gives every particle the held force
 * F_x = m 0.5 m/s^2. The host must call it once per level sharing the fluid
 * and take the table as it is (tests/abi/fluid_host_test.cpp).
 */
#include <stddef.h>

#include "broken/stub_callbacks.h"

static domel_status push(void* instance, domel_fluid_exchange_v1* ex, char* err, size_t err_capacity) {
  (void)instance;
  (void)err;
  (void)err_capacity;
  domel_particles_v1* p = ex->level->particles;
  for (size_t k = 0; k < p->n; ++k) p->fx[k] += 0.5 * p->mass[k];
  return DOMEL_OK;
}

/* the 2.1 table: struct_size up to the end of `exchange` */
static const domel_fluid_coupler_family_v1 kTable = {offsetof(domel_fluid_coupler_family_v1, fields), 0u, push,
                                                     NULL, NULL};
static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_FLUID_COUPLER, "abi21_push", "1.0.0", "ABI 2.1 fluid coupler: F_x = 0.5 m",
    STUB_SCHEMA, stub_create, stub_destroy, &kTable};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {sizeof(domel_library_v2), 2u, 1u, "abi21_fluid", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
