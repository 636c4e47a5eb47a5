// The event streams' queues: every client gets every batch once; a client that falls behind loses the
// waiting batches (drop-oldest) and is told to resynchronise, so a slow page holds no memory.
#include <gtest/gtest.h>

#include <thread>

#include "web/feed.hpp"

namespace {

using vsd::web::detail::Event;
using vsd::web::detail::Feed;
using vsd::web::detail::make_event;

TEST(Feed, EveryClientGetsEveryBatchInOrder) {
  Feed feed(8);
  auto a = feed.open(make_event("hello", "{}"));
  auto b = feed.open(make_event("hello", "{}"));
  EXPECT_EQ(feed.broadcast(make_event("changes", "{\"seq\":1}")), 0U);
  EXPECT_EQ(feed.broadcast(make_event("changes", "{\"seq\":2}")), 0U);
  std::vector<Event> got;
  ASSERT_TRUE(feed.wait(*a, got, std::chrono::milliseconds(0)));
  ASSERT_EQ(got.size(), 3U);
  EXPECT_EQ(*got[0], "event: hello\ndata: {}\n\n");
  EXPECT_EQ(*got[2], "event: changes\ndata: {\"seq\":2}\n\n");
  ASSERT_TRUE(feed.wait(*b, got, std::chrono::milliseconds(0)));
  EXPECT_EQ(got.size(), 3U);
  EXPECT_EQ(feed.clients(), 2U);
}

TEST(Feed, ASlowClientIsToldToResynchroniseAndHoldsNoMoreThanTheBacklog) {
  Feed feed(4);
  auto slow = feed.open(make_event("hello", "{}"));
  std::size_t dropped = 0;
  for (int i = 0; i < 100; ++i) dropped += feed.broadcast(make_event("changes", "{}"));
  EXPECT_GT(dropped, 0U);
  std::vector<Event> got;
  ASSERT_TRUE(feed.wait(*slow, got, std::chrono::milliseconds(0)));
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0]->rfind("event: resync\n", 0), 0U);
  EXPECT_TRUE(slow->queue.empty());
  feed.broadcast(make_event("changes", "{\"after\":1}"));
  ASSERT_TRUE(feed.wait(*slow, got, std::chrono::milliseconds(0)));
  ASSERT_EQ(got.size(), 1U);
  EXPECT_NE(got[0]->find("after"), std::string::npos);
}

TEST(Feed, ShutdownWakesAWaitingClient) {
  Feed feed(4);
  auto c = feed.open(make_event("hello", "{}"));
  std::vector<Event> got;
  ASSERT_TRUE(feed.wait(*c, got, std::chrono::milliseconds(0)));
  std::thread t([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    feed.shutdown();
  });
  EXPECT_FALSE(feed.wait(*c, got, std::chrono::seconds(10)));
  t.join();
  EXPECT_EQ(feed.clients(), 0U);
}

TEST(Feed, AClosedClientGetsNothingMore) {
  Feed feed(4);
  auto c = feed.open(make_event("hello", "{}"));
  feed.close(c);
  feed.broadcast(make_event("changes", "{}"));
  std::vector<Event> got;
  EXPECT_FALSE(feed.wait(*c, got, std::chrono::milliseconds(0)));
  EXPECT_EQ(feed.clients(), 0U);
}

}  // namespace
