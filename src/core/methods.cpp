#include <array>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"

namespace cmc33 {

namespace {
constexpr std::array<std::string_view, kSubcaseCount> kSubcaseNames = {
    "0",    "1",      "2",      "3.1",  "3.2",  "4.1.1", "4.1.2", "5",      "6.1.1",  "6.1.2", "6.2",
    "7.1",  "7.2",    "7.3",    "7.4.1", "7.4.2", "8",   "9",     "10.1.1", "10.1.2", "10.2",  "11",
    "12.1.1", "12.1.2", "12.2", "12.3", "13.1", "13.2",  "13.3",  "13.4",   "13.5.1", "13.5.2", "14"};
} // namespace

std::string_view method_name(Method method) noexcept
{
    switch (method) {
    case Method::cmc33: return "cmc33";
    case Method::mc33_lewiner: return "mc33-lewiner";
    case Method::mc: break;
    }
    return "mc";
}

Method parse_method(std::string_view name)
{
    for (Method m : {Method::cmc33, Method::mc33_lewiner, Method::mc}) {
        if (name == method_name(m)) return m;
    }
    throw Error(Status::invalid_argument,
                "unknown method '" + std::string(name) + "'; expected cmc33, mc33-lewiner or mc");
}

std::string_view subcase_name(int subcase) noexcept
{
    if (subcase < 0 || subcase >= kSubcaseCount) return "?";
    return kSubcaseNames[static_cast<std::size_t>(subcase)];
}

} // namespace cmc33
