#!/usr/bin/env bash
# `cmake --install` of this build into a temporary prefix, then used the two ways docs/install.md
# describes: tests/install/consumer, a program outside the tree that sees Inbetween only through
# find_package(Inbetween) with CMAKE_PREFIX_PATH=<prefix>, is configured, built and run (solver
# and client); and the installed `inbetween animate` runs on examples/square_hexagon. Also: the
# exported CMake files name no path of the build machine's trees, and `--component cli` installs
# the CLI alone (what the `inbetween` .deb holds).
source "$(dirname "$0")/lib/common.sh"
# A sanitizer build's archives need the sanitizer runtimes (and, for TSan, scripts/tsan-deps'
# instrumented gRPC) that the exported package does not carry: packaging is checked on plain builds.
if grep -qE '^INBETWEEN_(ASAN|TSAN):BOOL=ON' "$INBETWEEN_BIN/CMakeCache.txt"; then
  echo "SKIP: sanitizer build"; exit 77
fi
prefix="$WORK/prefix"
cmake --install "$INBETWEEN_BIN" --prefix "$prefix" >"$WORK/install.log"

config=$(find "$prefix" -path '*/cmake/Inbetween/InbetweenConfig.cmake')
[[ -n "$config" ]] || { echo "no InbetweenConfig.cmake under $prefix"; exit 1; }
for f in bin/inbetween bin/inbetween-server bin/inbetween-loadgen \
         include/inbetween/solver/mesh/build_multimesh.h include/inbetween/client/inbetween_client.h \
         include/inbetween/server/inbetween_server.h include/inbetween/inbetween/v1/inbetween.pb.h \
         include/inbetween/inbetween/v1/inbetween.grpc.pb.h include/inbetween/inbetween/v1/inbetween.proto; do
  [[ -f "$prefix/$f" ]] || { echo "not installed: $f"; exit 1; }
done
for lib in proto solver render server_lib client_lib; do
  [[ -f "$(dirname "$(dirname "$(dirname "$config")")")/libinbetween_$lib.a" ]] ||
    { echo "not installed: libinbetween_$lib.a"; exit 1; }
done
if grep -rn -e "$INBETWEEN_SRC" -e "$INBETWEEN_BIN" "$(dirname "$config")"; then
  echo "the exported CMake package names paths of the build machine (above)"; exit 1
fi

# The consumer from a copy, so nothing in it can reach the source tree by a relative path.
cp -r "$INBETWEEN_SRC/tests/install/consumer" "$WORK/consumer"
generator=(); command -v ninja >/dev/null && generator=(-G Ninja)
launcher=()
if command -v ccache >/dev/null; then
  # Repeated runs hit the cache: paths under $WORK (a new temp dir each run) hashed as relative.
  export CCACHE_BASEDIR="$WORK" CCACHE_NOHASHDIR=true
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S "$WORK/consumer" -B "$WORK/consumer-build" "${generator[@]}" "${launcher[@]}" \
  -DCMAKE_PREFIX_PATH="$prefix" >"$WORK/configure.log" 2>&1 ||
  { cat "$WORK/configure.log"; echo "consumer: configure failed"; exit 1; }
cmake --build "$WORK/consumer-build" >"$WORK/build.log" 2>&1 ||
  { cat "$WORK/build.log"; echo "consumer: build failed"; exit 1; }
if grep -rIl -e "$INBETWEEN_SRC" "$WORK/consumer-build"; then
  echo "the consumer's build names the source tree (files above)"; exit 1
fi
"$WORK/consumer-build/consumer" | tee "$WORK/consumer.out"
grep -qE '^solver: multimesh of [0-9]+ vertices, [1-9][0-9]* triangles; halfway frame: 0 inverted$' \
  "$WORK/consumer.out" || { echo "consumer: unexpected solver output"; exit 1; }
grep -qx 'client: created session "consumer", listed: yes' "$WORK/consumer.out" ||
  { echo "consumer: unexpected client output"; exit 1; }

ex="$INBETWEEN_SRC/examples/square_hexagon"
"$prefix/bin/inbetween" animate "$ex/square.svg" "$ex/hexagon.svg" --frames 12 --out "$WORK/anim" \
  --quiet >/dev/null
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/anim/frames.json" 12 0,11

cmake --install "$INBETWEEN_BIN" --prefix "$WORK/cli" --component cli >/dev/null
installed=$(cd "$WORK/cli" && find . -type f | sort)
[[ "$installed" == "./bin/inbetween" ]] || { echo "component cli installed: $installed"; exit 1; }
echo "ok"
