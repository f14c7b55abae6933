// cpfg's printf (Op::Printf of lsystem/detail/program.h).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include "lsystem/detail/program.h"

namespace sprig::lsystem::detail {

void printFormatted(const std::string& format, const double* args, int n) {
  std::string out, spec;
  char buf[512];
  int k = 0;
  for (size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') {
      out.push_back(format[i]);
      continue;
    }
    if (i + 1 < format.size() && format[i + 1] == '%') {
      out.push_back('%');
      ++i;
      continue;
    }
    spec.assign(1, '%');
    size_t j = i + 1;
    while (j < format.size() && std::string_view("-+ #0123456789.").find(format[j]) != std::string_view::npos) spec.push_back(format[j++]);
    while (j < format.size() && (format[j] == 'h' || format[j] == 'l' || format[j] == 'L')) ++j;  // length: ours
    if (j >= format.size() || k >= n) break;
    const char conv = format[j];
    const double v = args[k++];
    if (std::string_view("diouxXc").find(conv) != std::string_view::npos) {
      // Integers: cpfg passes its float; clamp into range (no out-of-range cast).
      const double t = std::isfinite(v) ? std::clamp(std::trunc(v), -9.0e18, 9.0e18) : 0.0;
      if (conv != 'c') spec.append("ll");
      spec.push_back(conv);
      if (conv == 'c') std::snprintf(buf, sizeof buf, spec.c_str(), static_cast<int>(std::clamp(t, 0.0, 255.0)));
      else std::snprintf(buf, sizeof buf, spec.c_str(), static_cast<long long>(t));
    } else {
      spec.push_back(conv);
      std::snprintf(buf, sizeof buf, spec.c_str(), v);
    }
    out += buf;
    i = j;
  }
  std::fputs(out.c_str(), stderr);
}


void arrayIndexError(const CpfgArray& a, int d, double i) {
  std::string shape = a.name;
  for (int n : a.dims) shape += "[" + std::to_string(n) + "]";
  char index[64];
  std::snprintf(index, sizeof index, "%.17g", i);
  std::string where = a.dims.size() > 1 ? " in its dimension " + std::to_string(d + 1) : std::string();
  throw InputError(SourceLoc{"sprig", 0, 0}, "index " + std::string(index) + where + " of cpfg's array '" + a.name +
                                                 "' is out of range (it is " + shape + ", indices 0 to " +
                                                 std::to_string(a.dims[d] - 1) + ")");
}

}  // namespace sprig::lsystem::detail
