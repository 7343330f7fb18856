/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case i): built against a newer minor of ABI 2 than the host
 * speaks (abi_minor = DOMEL_ABI_MINOR + 1). Such a plugin may rely on fields
 * the host does not fill, so the host must refuse it and say "newer".
 */
#include "stub_callbacks.h"

static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_TWISTING, "newer_minor_twisting", "1.0.0", "from the future",
    STUB_SCHEMA, stub_create, stub_destroy, &stub_contact_family};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR + 1, "newer_minor", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
