/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case a): a library descriptor that claims ABI major 2 while
 * exporting the v1 entry symbol. The loader must refuse it on the ABI major
 * before reading any model.
 */
#include "stub_callbacks.h"

static const domel_model_v1 kModel = {
    sizeof(domel_model_v1), DOMEL_KIND_NORMAL, "abi_major_2_normal", "1.0.0", "never registered",
    STUB_SCHEMA, 0u, 0u, stub_create, stub_destroy, stub_contact, NULL};
static const domel_model_v1* const kModels[] = {&kModel};
static const domel_library_v1 kLibrary = {
    sizeof(domel_library_v1), 2u, 0u, "abi_major_2", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v1* domel_plugin_entry_v1(void) { return &kLibrary; }
