#include <iterator>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "mc33_tables.hpp"

namespace cmc33 {

static_assert(std::size(detail::kSubcaseNames) == kSubcaseCount, "the generator's subcase list and kSubcaseCount differ");

std::string_view method_name(Method method) noexcept
{
    switch (method) {
    case Method::cmc33: return "cmc33";
    case Method::mc33_lewiner: return "mc33-lewiner";
    case Method::chernyaev: return "chernyaev";
    case Method::cmc33_paper: return "cmc33-paper";
    case Method::mc: break;
    }
    return "mc";
}

Method parse_method(std::string_view name)
{
    for (Method m : {Method::cmc33, Method::cmc33_paper, Method::chernyaev, Method::mc33_lewiner, Method::mc}) {
        if (name == method_name(m)) return m;
    }
    throw Error(Status::invalid_argument, "unknown method '" + std::string(name) +
                                              "'; expected cmc33, cmc33-paper, chernyaev, mc33-lewiner or mc");
}

std::string_view subcase_name(int subcase) noexcept
{
    if (subcase < 0 || subcase >= kSubcaseCount) return "?";
    return detail::kSubcaseNames[static_cast<std::size_t>(subcase)];
}

} // namespace cmc33
