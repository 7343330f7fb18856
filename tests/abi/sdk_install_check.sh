#!/usr/bin/env bash
# SDK install check, run by ctest (sdk_install_out_of_tree):
#   sdk_install_check.sh <domel build dir> <out-of-tree project dir>
# 1. installs the built domel project into a temporary prefix and checks the
#    SDK headers and the domel_sdk CMake package config are there;
# 2. configures and builds the out-of-tree plugin project against that prefix
#    (find_package(domel_sdk 1.0) + domel_add_plugin);
# 3. runs `domel plugins` (build tree, then the installed copy) with
#    DOMEL_PLUGIN_PATH at the built module and checks the model is listed;
# 4. removes the temporary folder, whatever happened.
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 <domel build dir> <out-of-tree project dir>" >&2
  exit 64
fi
build=$(cd "$1" && pwd)
project=$(cd "$2" && pwd)
model=oot_linear
library=my_plugin

tmp=$(mktemp -d "${TMPDIR:-/tmp}/domel_sdk_check.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix

fail() {
  echo "sdk_install_check: FAIL: $*" >&2
  exit 1
}

echo "== 1. install $build into $prefix"
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 || {
  cat "$tmp/install.log" >&2
  fail "cmake --install failed"
}
for f in include/domel/sdk/abi.h include/domel/sdk/plugin.hpp include/domel/sdk/kinematics.hpp \
         lib/cmake/domel_sdk/domel_sdkConfig.cmake lib/cmake/domel_sdk/domel_sdkConfigVersion.cmake \
         lib/cmake/domel_sdk/domel_sdk_targets.cmake lib/cmake/domel_sdk/DomelPlugin.cmake; do
  [[ -f "$prefix/$f" ]] || { (cd "$prefix" && find . -type f | sort) >&2; fail "not installed: $f"; }
done
echo "installed the SDK headers and lib/cmake/domel_sdk/"

echo "== 2. build $project against the installed SDK"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S "$project" -B "$tmp/oot-build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/configure.log" 2>&1 || {
  cat "$tmp/configure.log" >&2
  fail "configuring the out-of-tree project failed"
}
grep -q "domel_sdk_DIR:PATH=$prefix/lib/cmake/domel_sdk" "$tmp/oot-build/CMakeCache.txt" ||
  fail "find_package(domel_sdk) did not pick the installed package: $(grep domel_sdk_DIR "$tmp/oot-build/CMakeCache.txt")"
nice cmake --build "$tmp/oot-build" -j1 >"$tmp/build.log" 2>&1 || {
  cat "$tmp/build.log" >&2
  fail "building the out-of-tree plugin failed"
}
module=$(find "$tmp/oot-build" -maxdepth 2 -name "lib$library.so" -type f | head -n 1)
[[ -n "$module" ]] || fail "no lib$library.so under $tmp/oot-build"
echo "built $module"

echo "== 3. domel plugins lists '$model'"
list_plugins() {  # <domel executable>
  local out
  out=$(DOMEL_PLUGIN_PATH=$(dirname "$module") "$1" plugins 2>"$tmp/plugins.err") || {
    cat "$tmp/plugins.err" >&2
    fail "$1 plugins failed"
  }
  if ! grep -Eq "^library $library 0\.1\.0 \(ABI [0-9]+\.[0-9]+\) .*lib$library\.so$" <<<"$out"; then
    echo "$out" >&2
    fail "$1 plugins does not list library '$library'"
  fi
  if ! grep -Eq "^  normal +$model +0\.1\.0 " <<<"$out"; then
    echo "$out" >&2
    fail "$1 plugins does not list model '$model'"
  fi
  if grep "refused" "$tmp/plugins.err" | grep -q "lib$library\.so"; then
    cat "$tmp/plugins.err" >&2
    fail "$1 plugins refused lib$library.so"
  fi
  # Other refusals (e.g. the built-ins found both in the install and in the
  # build tree compiled into the binary) are not this check's business; show them.
  if grep -q "refused" "$tmp/plugins.err"; then
    echo "note: $1 plugins refused other libraries:"
    grep "refused" "$tmp/plugins.err" | sed 's/^/  /'
  fi
  grep -E "^library $library |^  normal +$model " <<<"$out"
}
list_plugins "$build/bin/domel"
[[ -x "$prefix/bin/domel" ]] || fail "not installed: bin/domel"
list_plugins "$prefix/bin/domel"

echo "== 4. clean up $tmp"
echo "sdk_install_check: OK"
