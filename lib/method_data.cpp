// Definition of method_data_for (declared in methods/method_data.hpp), compiled once in libnystrom.
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include "nystrom/methods/method_data.hpp"
#include "nystrom/methods/refine.hpp"

namespace nystrom {

MethodData method_data_for(const MethodDef& def, long bits, const std::string& type_name) {
  const unsigned ref = reference_bits(bits);
  BigPrecision guard(ref);
  MethodData data = def.build();
  const int digits = def.info.published_digits;
  if (published_digits_suffice(digits, bits)) return data;
  const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data);
  const std::string published = def.info.name + "'s coefficients are published with " + std::to_string(digits) +
                                " digits, too few for " + type_name + " (" + std::to_string(bits) + " bits)";
  if (!sp) throw std::invalid_argument(published + ", and only splitting methods can be refined to more");
  std::string key = def.info.name + "|" + std::to_string(def.info.order) + "|" + std::to_string(ref);
  for (const auto& st : sp->steps) key += "|" + st.coef.re.str(40) + "," + st.coef.im.str(40);
  static std::mutex mu;
  static std::map<std::string, SplittingScheme<bigcomplex>> cache;
  std::lock_guard<std::mutex> lock(mu);
  if (auto it = cache.find(key); it != cache.end()) return MethodData{it->second};
  Refinement r;
  try {
    r = refine_splitting(*sp, def.info.order, def.info.name);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(published + "; " + e.what());
  }
  cache.emplace(key, r.scheme);
  return MethodData{std::move(r.scheme)};
}

}  // namespace nystrom
