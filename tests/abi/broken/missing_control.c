/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case e, controller family): a controller whose family table
 * is truncated: its struct_size stops before the `control` callback, as a
 * table written against a smaller (hypothetical) layout would. The loader
 * must name 'control' as the missing callback.
 */
#include "stub_callbacks.h"

static const domel_controller_family_v1 kTruncated = {offsetof(domel_controller_family_v1, control), 0u, NULL};

static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_CONTROLLER, "missing_control_controller", "1.0.0", "no control callback",
    STUB_SCHEMA, stub_create, stub_destroy, &kTruncated};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "missing_control", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
