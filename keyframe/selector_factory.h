// Creates keyframe selectors by name with parameters (settings Keyframe.* / command line).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "keyframe/keyframe_selector.h"

namespace pkslam {

// Names accepted by MakeKeyframeSelector.
std::vector<std::string> KeyframeSelectorNames();

// Throws OptionError for an unknown name or parameter (naming it and listing valid ones).
std::unique_ptr<KeyframeSelector> MakeKeyframeSelector(
    const std::string& name, const std::map<std::string, double>& parameters = {});

}  // namespace pkslam
