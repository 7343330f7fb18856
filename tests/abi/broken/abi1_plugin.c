/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case a, the past direction): a plugin built against domel
 * SDK 1.1, as every plugin before ABI 2 was. It exports domel_plugin_entry_v1
 * returning an ABI-1 library description. SDK 2 no longer declares the ABI-1
 * types, so their layout is frozen here from SDK 1.1's abi.h (the leading
 * members, which is all the host reads: it calls the v1 entry only to name
 * the library and its version). This runtime refuses it, naming ABI 1.1 and
 * its own 2.x (docs/sdk-guide.md, "Versions").
 */
#include <domel/sdk/abi.h>

typedef struct sdk1_library_v1 {
  uint32_t struct_size;
  uint32_t abi_major;
  uint32_t abi_minor;
  const char* name;
  const char* version;
  uint32_t model_count;
  const void* const* models; /* domel_model_v1 of SDK 1 */
} sdk1_library_v1;

static const sdk1_library_v1 kLibrary = {sizeof(sdk1_library_v1), 1u, 1u, "abi1_plugin", "0.9.0", 0u, NULL};

DOMEL_EXPORT const sdk1_library_v1* domel_plugin_entry_v1(void) { return &kLibrary; }
