/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case a, the future direction): a library description that
 * claims ABI 3.0 while exporting the v2 entry symbol, as a plugin of a future
 * SDK might. The loader must refuse it on the ABI major before reading any
 * model, naming both versions (3.0 and this runtime's 2.x).
 */
#include "stub_callbacks.h"

static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_NORMAL, "abi_major_3_normal", "1.0.0", "never registered",
    STUB_SCHEMA, stub_create, stub_destroy, &stub_contact_family};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), 3u, 0u, "abi_major_3", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
