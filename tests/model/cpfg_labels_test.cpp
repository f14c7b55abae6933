#include <catch2/catch.hpp>

#include "model/cpfg_labels.h"

using namespace sprig;

TEST_CASE("cpfgLabelFont", "[model]") {
  // cpfg's default, -*-courier-bold-r-*-*-12-*-...: a bold fixed-width font of 12 points.
  CHECK(cpfgLabelFont("").file == std::string(kLabelFontFolder) + "/DejaVuSansMono-Bold.ttf");
  CHECK(cpfgLabelFont("").sizePixels == 16);
  // Borcher-Honda's -*-*-*-r-*-*-10-*-...: Qt's default family, regular, 10 points.
  CHECK(cpfgLabelFont("-*-*-*-r-*-*-10-*-*-*-*-*-*-*").file == std::string(kLabelFontFolder) + "/DejaVuSans.ttf");
  CHECK(cpfgLabelFont("-*-*-*-r-*-*-10-*-*-*-*-*-*-*").sizePixels == 13);
  CHECK(cpfgLabelFont("-adobe-times-medium-italic-normal--0-140-*-*-p-*-iso8859-1").file ==
        std::string(kLabelFontFolder) + "/DejaVuSerif-BoldItalic.ttf");  // size field 7 is 140: field 6 (0), then 12
  CHECK(cpfgLabelFont("fixed").sizePixels == 12);  // not an X11 name: Qt's default, 9 points
}
