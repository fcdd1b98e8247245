#include "base/errors.hpp"

#include <new>

namespace tracer {

Failure failure_of(std::exception_ptr e) {
  using Kind = Failure::Kind;
  try {
    std::rethrow_exception(std::move(e));
  } catch (const UsageError& x) {
    return {Kind::Usage, 2, x.what()};
  } catch (const InputError& x) {
    return {Kind::Input, 1, x.what()};
  } catch (const Cancelled& x) {
    return {Kind::Cancelled, 130, x.what()};
  } catch (const std::bad_alloc&) {
    return {Kind::OutOfMemory, 1, "out of memory"};
  } catch (const std::exception& x) {
    return {Kind::Internal, 1, x.what()};
  } catch (...) {
    return {Kind::Internal, 1, "an exception of unknown type"};
  }
}

}  // namespace tracer
