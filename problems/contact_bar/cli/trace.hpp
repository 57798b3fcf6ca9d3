// The contact bar as a problem of the `backbone` CLI, without its benchmarks and figures: its
// scene keys, its `trace` branches and their setups, `simulate` (simulate.hpp) and the units of
// its observables. plugin.cpp adds the benchmarks, the figures and the main job's steps; the
// benchmarks run their traces through this plugin, exactly as `backbone trace` does.
//
//   const cli::ProblemPlugin plugin = contact_bar::trace_plugin();
//   cli::TraceSetup setup = plugin.setup(scene, "mode1");
#pragma once

#include "continuation/cli/plugin.hpp"

namespace backbone::contact_bar {

cli::ProblemPlugin trace_plugin();

}  // namespace backbone::contact_bar
