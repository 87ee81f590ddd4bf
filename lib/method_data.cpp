// Definition of method_data_for (declared in methods/method_data.hpp), compiled once in libnystrom.
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

#include "nystrom/methods/catalog.hpp"
#include "nystrom/methods/method_data.hpp"
#include "nystrom/methods/refine.hpp"

namespace nystrom {

namespace {

/// Whether `def` is the catalog's entry of its name (the same record): its coefficients are then a function of
/// the name and the precision, and are built once per precision.
bool is_catalog_entry(const MethodDef& def) {
  for (const auto& d : catalog())
    if (d.info.name == def.info.name)
      return d.info.family == def.info.family && d.info.order == def.info.order && d.info.source == def.info.source &&
             d.info.description == def.info.description;
  return false;
}

/// def.build() at the current reference precision; for a catalog entry, from a cache (building a table in MPFR
/// costs 40-220 microseconds, more than a short run of the method; copying it, 5-20).
std::shared_ptr<const MethodData> built(const MethodDef& def, unsigned ref) {
  if (!is_catalog_entry(def)) return std::make_shared<const MethodData>(def.build());
  static std::mutex mu;
  static std::map<std::pair<std::string, unsigned>, std::shared_ptr<const MethodData>> cache;
  const auto key = std::make_pair(def.info.name, ref);
  {
    std::lock_guard<std::mutex> lock(mu);
    if (auto it = cache.find(key); it != cache.end()) return it->second;
  }
  auto data = std::make_shared<const MethodData>(def.build());
  std::lock_guard<std::mutex> lock(mu);
  return cache.emplace(key, std::move(data)).first->second;
}

}  // namespace

std::shared_ptr<const MethodData> shared_method_data_for(const MethodDef& def, long bits,
                                                         const std::string& type_name) {
  const unsigned ref = reference_bits(bits);
  BigPrecision guard(ref);
  std::shared_ptr<const MethodData> data = built(def, ref);
  const int digits = def.info.published_digits;
  if (published_digits_suffice(digits, bits)) return data;
  const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(data.get());
  const std::string published = def.info.name + "'s coefficients are published with " + std::to_string(digits) +
                                " digits, too few for " + type_name + " (" + std::to_string(bits) + " bits)";
  if (!sp) throw std::invalid_argument(published + ", and only splitting methods can be refined to more");
  std::string key = def.info.name + "|" + std::to_string(def.info.order) + "|" + std::to_string(ref);
  for (const auto& st : sp->steps) key += "|" + st.coef.re.str(40) + "," + st.coef.im.str(40);
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<const MethodData>> cache;
  std::lock_guard<std::mutex> lock(mu);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  Refinement r;
  try {
    r = refine_splitting(*sp, def.info.order, def.info.name);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(published + "; " + e.what());
  }
  return cache.emplace(key, std::make_shared<const MethodData>(std::move(r.scheme))).first->second;
}

MethodData method_data_for(const MethodDef& def, long bits, const std::string& type_name) {
  std::shared_ptr<const MethodData> data = shared_method_data_for(def, bits, type_name);
  BigPrecision guard(reference_bits(bits));  // the copy keeps the reference precision
  return *data;
}

}  // namespace nystrom
