/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case g, second half): one library that lists two normal
 * models both named "duplicate_twin". Same name under another kind would be
 * legal; same (kind, name) twice is not.
 */
#include "stub_callbacks.h"

static const domel_model_v2 kFirst = {
    sizeof(domel_model_v2), DOMEL_KIND_NORMAL, "duplicate_twin", "1.0.0", "first twin",
    STUB_SCHEMA, stub_create, stub_destroy, &stub_contact_family};
static const domel_model_v2 kSecond = {
    sizeof(domel_model_v2), DOMEL_KIND_NORMAL, "duplicate_twin", "2.0.0", "second twin",
    STUB_SCHEMA, stub_create, stub_destroy, &stub_contact_family};
static const domel_model_v2* const kModels[] = {&kFirst, &kSecond};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "duplicate_within", "1.0.0", 2u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
