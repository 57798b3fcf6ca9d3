// core/job_queue: run_tasks runs each task once with the calling thread among the workers;
// SerialQueue runs its tasks one at a time in the order pushed, rethrows the first exception at
// wait() (the later tasks still run), and drops the tasks not begun when it is destroyed.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/job_queue.hpp"

namespace {

using namespace backbone::core;

TEST(RunTasks, EachTaskRunsOnceAndTheCallingThreadTakesPart) {
  // The tasks are taken dynamically: every index exactly once, whatever the number of threads
  // (also more threads than tasks), and the calling thread is one of the workers. With 2
  // threads, task 0 waits until the other four have run: only the other thread can run them
  // meanwhile (striped, thread 0 would have to run tasks 2 and 4 itself; the wait gives up
  // after 10 s and the count below fails).
  for (int threads : {1, 2, 3, 8}) {
    const int tasks = 5;
    std::vector<int> runs(tasks, 0);
    std::vector<std::thread::id> who(tasks);
    std::atomic<int> done{0};
    run_tasks(tasks, threads, [&](int t) {
      if (t == 0 && threads == 2) {
        const auto start = std::chrono::steady_clock::now();
        while (done < tasks - 1 &&
               std::chrono::steady_clock::now() - start < std::chrono::seconds(10))
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      runs[static_cast<std::size_t>(t)]++;
      who[static_cast<std::size_t>(t)] = std::this_thread::get_id();
      done++;
    });
    EXPECT_EQ(runs, std::vector<int>(tasks, 1)) << threads << " threads";
    if (threads <= 2) {  // with more threads the workers may take every task first
      EXPECT_NE(std::find(who.begin(), who.end(), std::this_thread::get_id()), who.end());
    }
    if (threads == 2) {
      EXPECT_EQ(std::count(who.begin(), who.end(), who[0]), 1);
    }
  }
}

TEST(SerialQueue, RunsTheTasksInTheOrderPushedOnOneOtherThread) {
  SerialQueue queue;
  std::vector<int> order;  // written by the queue's thread only, read after wait()
  std::vector<std::thread::id> who;
  for (int t = 0; t < 50; ++t)
    queue.push([&order, &who, t] {
      order.push_back(t);
      who.push_back(std::this_thread::get_id());
    });
  queue.wait();
  ASSERT_EQ(order.size(), 50u);
  for (int t = 0; t < 50; ++t) EXPECT_EQ(order[static_cast<std::size_t>(t)], t);
  EXPECT_EQ(std::count(who.begin(), who.end(), who[0]), 50);
  EXPECT_NE(who[0], std::this_thread::get_id());
}

TEST(SerialQueue, WaitRethrowsTheFirstExceptionAndTheLaterTasksStillRun) {
  SerialQueue queue;
  int after = 0;
  queue.push([] { throw std::runtime_error("first"); });
  queue.push([] { throw std::logic_error("second"); });
  queue.push([&after] { ++after; });
  try {
    queue.wait();
    ADD_FAILURE() << "wait() did not rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");
  }
  EXPECT_EQ(after, 1);
  EXPECT_THROW(queue.rethrow(), std::runtime_error);  // kept: every later call reports it
}

TEST(SerialQueue, RethrowDoesNotWaitAndIsSilentWithoutAnError) {
  SerialQueue queue;
  std::atomic<bool> release{false};
  queue.push([&release] {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  EXPECT_NO_THROW(queue.rethrow());  // the task still runs: rethrow() returned without it
  release = true;
  EXPECT_NO_THROW(queue.wait());
}

TEST(SerialQueue, TheDestructorDropsTheTasksNotBegun) {
  std::atomic<bool> started{false}, second_ran{false};
  {
    SerialQueue queue;
    queue.push([&started] {
      started = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    });
    queue.push([&second_ran] { second_ran = true; });
    while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }  // the first task is still sleeping: the second has not begun
  EXPECT_FALSE(second_ran);
}

}  // namespace
