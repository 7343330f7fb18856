/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case b): what an SDK-2 plugin looks like to this host — it
 * exports domel_plugin_entry_v2 and not domel_plugin_entry_v1. The loader
 * must say it was built against ABI 2.x rather than "not a plugin". The v2
 * entry is never called, so its return type here does not matter.
 */
#include <domel/sdk/abi.h>

DOMEL_EXPORT const void* domel_plugin_entry_v2(void) { return NULL; }
