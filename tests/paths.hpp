// Where the tests find the source tree and the mechopt binary. The paths
// live in one generated file of the build (test_paths.cpp, tests/
// CMakeLists.txt), not in the test objects, so that those do not depend
// on where the clone is: ccache (CCACHE_BASEDIR) reuses them across clones.
#pragma once

namespace mechopt_test {
extern const char* const source_dir;  // the source tree's root
extern const char* const binary;      // build/bin/mechopt
}  // namespace mechopt_test

#define MECHOPT_SOURCE_DIR (::mechopt_test::source_dir)
#define MECHOPT_BINARY (::mechopt_test::binary)
