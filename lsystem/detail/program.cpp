// cpfg's printf (Op::Printf of lsystem/detail/program.h).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include "lsystem/detail/program.h"

namespace sprig::lsystem::detail {

std::string formatPrintf(const std::string& format, const double* args, int n) {
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
  return out;
}

void printFormatted(const std::string& format, const double* args, int n) {
  std::fputs(formatPrintf(format, args, n).c_str(), stderr);
}

int CpfgFiles::open(const std::string& name, const std::string& mode) {
  if (free_.empty())
    throw InputError(SourceLoc{"sprig", 0, 0}, "cpfg's fopen(\"" + name + "\"): more than " + std::to_string(kMaxFiles) +
                                                   " files open at once (cpfg's limit)");
  const std::string path = folder_.empty() ? name : folder_ + "/" + name;
  const int free = free_.back();
  files_[free] = std::fopen(path.c_str(), mode == "a" ? "ab" : "wb");
  if (files_[free]) free_.pop_back();
  else throw InputError(SourceLoc{"sprig", 0, 0}, "cpfg's fopen cannot open '" + path + "' for writing");
  return free;
}

std::FILE* CpfgFiles::at(double f) const {
  // cpfg's IsValidFpIndex and Getfp: an index out of range or a closed file is only a
  // message in cpfg, nothing written.
  if (!(f >= 0 && f < kMaxFiles)) return nullptr;
  return files_[static_cast<int>(f)];
}

void CpfgFiles::print(double f, const std::string& format, const double* args, int n) {
  if (std::FILE* fp = at(f)) std::fputs(formatPrintf(format, args, n).c_str(), fp);
}

void CpfgFiles::flush(double f) {
  if (std::FILE* fp = at(f)) std::fflush(fp);
}

void CpfgFiles::close(double f) {
  if (std::FILE* fp = at(f)) {
    std::fclose(fp);
    files_[static_cast<int>(f)] = nullptr;
    free_.push_back(static_cast<int>(f));
  }
}

void CpfgFiles::closeAll() {
  for (int k = 0; k < kMaxFiles; ++k) close(k);
  free_.clear();
  for (int k = 0; k < kMaxFiles; ++k) free_.push_back(k);
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
