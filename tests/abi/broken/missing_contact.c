/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case e): a tangential (contact-kind) model whose contact
 * kernel is NULL. create and destroy are present, so the loader must name
 * 'contact' as the missing member.
 */
#include "stub_callbacks.h"

static const domel_model_v1 kModel = {
    sizeof(domel_model_v1), DOMEL_KIND_TANGENTIAL, "missing_contact_tangential", "1.0.0", "has no kernel",
    STUB_SCHEMA, 0u, 0u, stub_create, stub_destroy, NULL, NULL};
static const domel_model_v1* const kModels[] = {&kModel};
static const domel_library_v1 kLibrary = {
    sizeof(domel_library_v1), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "missing_contact", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v1* domel_plugin_entry_v1(void) { return &kLibrary; }
