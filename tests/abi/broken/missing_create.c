/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case d): the second of two models has create == NULL. The
 * first model is valid, so the test can also prove that a refused library
 * registers none of its models (no partial registration).
 */
#include "stub_callbacks.h"

static const domel_model_v2 kValid = {
    sizeof(domel_model_v2), DOMEL_KIND_DAMPING, "missing_create_valid", "1.0.0", "valid sibling",
    STUB_SCHEMA, stub_create, stub_destroy, &stub_contact_family};
static const domel_model_v2 kNoCreate = {
    sizeof(domel_model_v2), DOMEL_KIND_NORMAL, "missing_create_normal", "1.0.0", "has no create",
    STUB_SCHEMA, NULL, stub_destroy, &stub_contact_family};
static const domel_model_v2* const kModels[] = {&kValid, &kNoCreate};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "missing_create", "1.0.0", 2u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
