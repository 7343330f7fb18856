# Sourced by the third-party example checks (third_party_*_check.sh): steps 1
# and 2 of each, the same for every example.
#   install_and_build_example <domel build dir> <example dir> <tmp dir> <module file name>
# installs the built domel project into <tmp>/prefix, configures and builds
# the example against that prefix only (find_package(domel_sdk) +
# domel_add_plugin) into <tmp>/build, and checks that the module is there and
# that the installed SDK package was the one found. Sets `domel` to the
# installed executable. Calls the caller's `fail` on any problem.
install_and_build_example() {
  local build=$1 project=$2 tmp=$3 module_name=$4
  local prefix=$tmp/prefix
  echo "== 1. install $build into $prefix"
  cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 || {
    cat "$tmp/install.log" >&2
    fail "cmake --install failed"
  }
  [[ -f "$prefix/lib/cmake/domel_sdk/domel_sdkConfig.cmake" ]] || fail "not installed: lib/cmake/domel_sdk/domel_sdkConfig.cmake"
  [[ -x "$prefix/bin/domel" ]] || fail "not installed: bin/domel"
  domel=$prefix/bin/domel

  echo "== 2. build $project against the installed SDK"
  local generator=()
  if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
  cmake -S "$project" -B "$tmp/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/configure.log" 2>&1 || {
    cat "$tmp/configure.log" >&2
    fail "configuring the example failed"
  }
  grep -q "domel_sdk_DIR:PATH=$prefix/lib/cmake/domel_sdk" "$tmp/build/CMakeCache.txt" ||
    fail "find_package(domel_sdk) did not pick the installed package: $(grep domel_sdk_DIR "$tmp/build/CMakeCache.txt")"
  nice cmake --build "$tmp/build" -j1 >"$tmp/build.log" 2>&1 || {
    cat "$tmp/build.log" >&2
    fail "building the example failed"
  }
  [[ -f "$tmp/build/$module_name" ]] || fail "no $module_name in $tmp/build"
  echo "built $tmp/build/$module_name"
}
