// One MPI process's view of the job: initialisation with the thread support tracer-mpi needs,
// its rank and the job's size, and the small collectives the driver uses.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

namespace tracer::mpi {

class MpiSession {
 public:
  // MPI_Init_thread asking for MPI_THREAD_MULTIPLE: a rank's render threads each ask rank 0 for
  // tiles (serialised by a mutex, so MPI_THREAD_SERIALIZED is enough and is what is required).
  // Throws std::runtime_error if the library offers less.
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }

  // Every rank's string, on rank 0 (empty elsewhere).
  std::vector<std::string> gather_strings(const std::string& mine) const;
  // Every rank's value, on every rank.
  std::vector<uint64_t> all_gather(uint64_t mine) const;
  // Rank 0's value, on every rank.
  int broadcast(int value) const;

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace tracer::mpi
