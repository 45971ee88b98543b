# Sourced by scripts/build.sh and the tests that build a copy of the tree:
# build through ccache when it is installed. Paths below CCACHE_BASEDIR (the
# tree, unless the caller set one) are hashed relative to the build, so a copy
# of the tree inside the build folder, built at the same depth below its own
# sources, hits the objects of the tree's own build; the sloppiness lets the
# precompiled header be cached.
#   source scripts/ccache-env.sh TREE
# Sets drift_launcher, the CMake arguments to add (empty without ccache).
drift_launcher=()
if command -v ccache >/dev/null && [[ ${CCACHE_DISABLE:-} != 1 ]]; then
  drift_launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$1}"
  export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"
fi
