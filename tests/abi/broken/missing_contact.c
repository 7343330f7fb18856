/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case e): a tangential (contact-kind) model whose contact
 * kernel is NULL in its contact family table. create, destroy and the table
 * are present, so the loader must name 'contact' as the missing callback.
 */
#include "stub_callbacks.h"

static const domel_contact_family_v2 kNoKernel = {sizeof(domel_contact_family_v2), 0u, NULL};

static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_TANGENTIAL, "missing_contact_tangential", "1.0.0", "has no kernel",
    STUB_SCHEMA, stub_create, stub_destroy, &kNoKernel};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "missing_contact", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
