// Reading the images a user points omnical at: a directory or glob pattern of files, each
// read with a completeness check first.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace omnical {

// A directory (its images, sorted) or a glob pattern, sorted. Throws InputError naming
// `where` if nothing matches.
std::vector<std::string> ListImages(const std::string& where);

// cv::imread with a check first that a PNG is complete (its last chunk is IEND): libpng
// would print its own "Read Error" line for a truncated file. Empty Mat if unreadable.
cv::Mat ReadImageFile(const std::string& path, int flags);

}  // namespace omnical
