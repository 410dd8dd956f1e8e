# Precompiled headers: the external headers most of rcfd's sources include, parsed once per target
# instead of once per source. Eigen, nlohmann-json and the standard library take 4-5 s of a compile
# of their own, GoogleTest and Boost.Beast as long again; they change only with the system's packages.
# Build time only: the compiled code is the same. A source with flags of its own (the kernels'
# -fno-math-errno, which GCC's PCH check refuses) sets SKIP_PRECOMPILE_HEADERS.
# With -DRCFD_PRECOMPILED_HEADERS=OFF every source parses its own includes, which also checks that
# each header includes what it uses.

# The headers of the solver library, its command line, the tests and the benches.
set(RCFD_PCH_SOLVER
    <algorithm> <array> <cmath> <cstdint> <filesystem> <fstream> <functional> <map> <memory>
    <optional> <sstream> <string> <vector> <Eigen/Core> <nlohmann/json.hpp>)
# The server's: Boost.Beast and Asio (whose awaitable.hpp uses std::exchange without <utility>).
set(RCFD_PCH_SERVER
    <utility> <chrono> <filesystem> <map> <memory> <optional> <string> <vector> <boost/asio.hpp>
    <boost/beast/core.hpp> <boost/beast/http.hpp> <nlohmann/json.hpp>)

# rcfd_precompile(TARGET HEADERS...): TARGET precompiles HEADERS (no-op when the option is off).
function(rcfd_precompile target)
  if(RCFD_PRECOMPILED_HEADERS)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()
