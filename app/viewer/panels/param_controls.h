// The Parameters panel's controls, one per entry of the parameter table (app/cli/param_table.h):
// the control's kind, range and names come from the table, and a knob the current scheme does
// not read is drawn greyed out.
#pragma once

#include "app/cli/param_table.h"

namespace lancer::viewer {

/// Draw the control of `d` editing `k` (greyed out, and not editable, when `d` does not apply to
/// `k`). Returns true when the user changed the value; the caller asks cli::changeEffect what the
/// change needs. `maxThreads` is the top of the threads slider (the table's range goes further).
bool paramControl(const cli::ParamDesc& d, cli::Knobs& k, int maxThreads);

/// The controls of every panel entry of the table whose effect is `effect` (the subdivision's
/// knobs: Rebuild; the rendering's: Rerender), in the table's order. Returns true on a change.
bool paramControls(cli::ChangeEffect effect, cli::Knobs& k, int maxThreads);

}  // namespace lancer::viewer
