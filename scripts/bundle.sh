#!/usr/bin/env bash
# Packs the Release build (build/) into one archive that runs on another x86-64 Linux machine
# with a GPU driver but none of Debian's packages (a lent GPU machine): the binaries, every
# library they link but glibc's, Debian's Vulkan validation layer and the suite's ctest files,
# with an unpack script. On that machine, from a checkout of the same commit:
#
#   tar xJf pbflow_bundle.tar.xz -C /opt && eval "$(/opt/pbflow/unpack.sh)"   # then build/pbflow, ctest
#
# The wrappers start the binaries through the dynamic loader with the bundle's libraries, not
# through LD_LIBRARY_PATH, so that the python3 and ffmpeg pbflow starts keep the machine's own.
#
#   scripts/bundle.sh [OUT]   (default build/pbflow_bundle.tar.xz)
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${1:-build/pbflow_bundle.tar.xz}")
layer=/usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage"/pbflow/{bin,lib,layers,ctest/tests}
cp build/pbflow build/tests/pbflow_tests "$stage/pbflow/bin/"
strip --strip-unneeded "$stage"/pbflow/bin/*
# glibc and the C++ runtime stay the machine's (newer there, and shared with its GPU driver).
ldd build/pbflow build/tests/pbflow_tests "$layer" | awk '/=> \//{print $3}' | sort -u |
  grep -Ev '/(libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s)\.so' | xargs -I{} cp -L {} "$stage/pbflow/lib/"
for gl in libEGL.so.1 libGLdispatch.so.0 libOpenGL.so.0 libGL.so.1 libGLX.so.0; do  # loaded by libepoxy at run time
  cp -L "/usr/lib/x86_64-linux-gnu/$gl" "$stage/pbflow/lib/"
done
cp "$layer" "$stage/pbflow/layers/"
sed 's#"library_path": "libVkLayer#"library_path": "./libVkLayer#' \
  /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json > "$stage/pbflow/layers/VkLayer_khronos_validation.json"
cp build/CTestTestfile.cmake "$stage/pbflow/ctest/"
cp build/tests/CTestTestfile.cmake build/tests/pbflow_tests*.cmake "$stage/pbflow/ctest/tests/"
cat > "$stage/pbflow/unpack.sh" <<'UNPACK'
#!/usr/bin/env bash
# From the checkout's root: the ctest files and the wrappers where the build would be. The
# tests name the build's own paths (/work/main); a link stands in where they are missing.
set -euo pipefail
here=$(dirname "$(realpath "$0")")
src=$(sed -n 's/^# Source directory: \(.*\)$/\1/p' "$here/ctest/CTestTestfile.cmake")
[ -e "$src" ] || { mkdir -p "$(dirname "$src")"; ln -s "$PWD" "$src"; }
mkdir -p build/tests
cp "$here/ctest/CTestTestfile.cmake" build/ && cp "$here"/ctest/tests/* build/tests/
for b in pbflow tests/pbflow_tests; do
  printf '#!/bin/sh\nexec /lib64/ld-linux-x86-64.so.2 --library-path %s/lib %s/bin/%s "$@"\n' "$here" "$here" \
    "$(basename $b)" > "build/$b"
  chmod +x "build/$b"
done
echo "export VK_LAYER_PATH=$here/layers  # the validation layer the tests ask for"
UNPACK
chmod +x "$stage/pbflow/unpack.sh"
tar cJf "$out" -C "$stage" pbflow
echo "bundle: $out ($(du -h "$out" | cut -f1))"
