// bireg: deterministic parallel sums over observations. The observations
// are cut into chunks of kChunkSize, a number independent of the thread
// count; each chunk's partial sum is computed by whichever thread claims
// it, and the partial sums are combined in chunk order by the caller. The
// arithmetic is therefore the same for any thread count, including one:
// a serial fit of more than one chunk adds the same partial sums in the
// same order, so results are bit-identical whatever `threads` is.
//
// ChunkPool starts threads - 1 workers once (per fit) and reuses them for
// every sum; the calling thread works too. A run publishes a function
// pointer and a context (no std::function, no allocation per run).
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace bireg {

// Observations per chunk of a parallel sum.
inline constexpr std::size_t kChunkSize = 4096;

// Below this many observations a fit stays serial whatever `threads` is:
// waking the workers costs more than the chunks they would share.
inline constexpr std::size_t kParallelMinimum = 2 * kChunkSize;

inline std::size_t chunk_count(std::size_t n) {
  return (n + kChunkSize - 1) / kChunkSize;
}

class ChunkPool {
 public:
  explicit ChunkPool(int threads) {
    const std::size_t worker_count = threads > 1 ? static_cast<std::size_t>(threads - 1) : 0;
    workers_.reserve(worker_count);
    for (std::size_t k = 0; k < worker_count; ++k)
      workers_.emplace_back([this] { serve(); });
  }
  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;
  ~ChunkPool() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& worker : workers_)
      worker.join();
  }

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(chunk) once for every chunk in [0, chunks), on any thread,
  // and returns when all calls have returned. body must not throw.
  template <class Body>
  void run(std::size_t chunks, const Body& body) {
    if (workers_.empty() || chunks < 2) {
      for (std::size_t chunk = 0; chunk < chunks; ++chunk)
        body(chunk);
      return;
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      task_ = [](const void* context, std::size_t chunk) {
        (*static_cast<const Body*>(context))(chunk);
      };
      context_ = &body;
      chunks_ = chunks;
      next_.store(0);
      busy_ = workers_.size();
      ++generation_;
    }
    wake_.notify_all();
    drain();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });
  }

 private:
  void drain() {
    for (std::size_t chunk = next_.fetch_add(1); chunk < chunks_; chunk = next_.fetch_add(1)) {
      task_(context_, chunk);
    }
  }

  void serve() {
    std::size_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
        if (stopping_) return;
        seen = generation_;
      }
      drain();
      const std::lock_guard<std::mutex> lock(mutex_);
      if (--busy_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::size_t generation_ = 0;
  bool stopping_ = false;
  void (*task_)(const void*, std::size_t) = nullptr;
  const void* context_ = nullptr;
  std::size_t chunks_ = 0;
  std::atomic<std::size_t> next_{0};
  std::size_t busy_ = 0;
};

// A once-per-fit pass over observations [0, n) (the observation check, the
// chart, the Gauss-Newton moments, the diagnostics) by chunks:
// body(begin, end) returns a chunk's Partial, and combine(total, next)
// folds the partials into the first in chunk order, so the result is the
// same arithmetic with or without a pool, for any thread count. One chunk
// calls body(0, n) and allocates nothing; more allocate their partials
// once (not for the iteration's loop: the force keeps its own workspace).
template <class Partial, class Body, class Combine>
Partial reduce_chunks(std::size_t n, ChunkPool* pool, const Body& body, const Combine& combine) {
  const std::size_t chunks = chunk_count(n);
  if (chunks <= 1) return body(std::size_t(0), n);
  std::vector<Partial> partials(chunks);
  const auto run_chunk = [&](std::size_t chunk) {
    partials[chunk] = body(chunk * kChunkSize, std::min(n, (chunk + 1) * kChunkSize));
  };
  if (pool) {
    pool->run(chunks, run_chunk);
  } else {
    for (std::size_t chunk = 0; chunk < chunks; ++chunk)
      run_chunk(chunk);
  }
  Partial total = std::move(partials[0]);
  for (std::size_t chunk = 1; chunk < chunks; ++chunk)
    combine(total, partials[chunk]);
  return total;
}

}  // namespace bireg
