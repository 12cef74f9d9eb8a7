#pragma once
// Which build of the scanner wrote an output: the version (CMake's project version) and the
// commit of the checkout it was built from.

namespace ihs::app {

/// `git describe --always --dirty` of the checkout when the binaries were built ("-dirty": with
/// changes not committed), or "unknown" when it was not a git checkout.
const char* BuildCommit();

/// The project's version (CMakeLists.txt's project version).
inline const char* BuildVersion() { return IHS_VERSION; }

}  // namespace ihs::app
