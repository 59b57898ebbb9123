// The one JSON reader of the documents motionfield reads with nlohmann/json
// (constraints files and inline constraints, rig anatomy files): strict where
// nlohmann is lenient. A key given twice in one object is refused with the
// key and the place (nlohmann would keep the last one silently), as the
// CLI's batch lines and the rig maps refuse it.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace mf {

/// Parses `text` (named `source` in messages). Throws InputError
/// "<source>: not valid JSON (<reason>)" or "<source>: duplicate key "<key>"
/// in <place>", <place> being "the top-level object" or the path of the
/// object holding it ("targets[1]", "keys[0].joints").
nlohmann::json parse_json_strict(const std::string& text, const std::string& source);

}  // namespace mf
