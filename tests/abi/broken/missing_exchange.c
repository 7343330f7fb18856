/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case e, fluid_coupler family): a fluid coupler whose family
 * table is complete but whose `exchange` callback is NULL. The loader must
 * name 'exchange' as the missing callback.
 */
#include "stub_callbacks.h"

static const domel_fluid_coupler_family_v1 kNoExchange = {sizeof(domel_fluid_coupler_family_v1), 0u, NULL};

static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_FLUID_COUPLER, "missing_exchange_coupler", "1.0.0", "no exchange callback",
    STUB_SCHEMA, stub_create, stub_destroy, &kNoExchange};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "missing_exchange", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
