/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case b, the future direction): what an SDK-3 plugin looks
 * like to this host — it exports domel_plugin_entry_v3 and not
 * domel_plugin_entry_v2. The loader must say it was built for ABI 3.x and
 * that this runtime speaks 2.x, rather than "not a plugin". The v3 entry is
 * never called, so its return type here does not matter.
 */
#include <domel/sdk/abi.h>

DOMEL_EXPORT const void* domel_plugin_entry_v3(void) { return NULL; }
