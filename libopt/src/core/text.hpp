// Numbers and lists as text, for messages and printed tables: every part
// above core writes them this one way.
#pragma once
#include <string>
#include <vector>

namespace opt::text {

// v with `precision` significant digits; "-" when not finite.
std::string fmt(double v, int precision = 6);
// The items separated by ", ".
std::string join(const std::vector<std::string>& v);

}  // namespace opt::text
