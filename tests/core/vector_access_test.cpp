// Tests of the element access of vector MetaTypes (MetaType::vector_size/get/set/push): the same calls
// serve std::vector<T> of every built-in type (vector<bool> too) and run-time vectors of run-time enums
// and structs, by copy, with a clear vsd::Error for an index out of range or a type that is no vector.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vsd/vsd.hpp>

using testing::HasSubstr;
using testing::ThrowsMessage;

namespace {

TEST(VectorAccess, ServesStdVectorsOfBuiltInTypes) {
  vsd::Value v(std::vector<double>{1.5, 2.5});
  const vsd::MetaType& t = *v.type();
  ASSERT_NE(t.ops().vector, nullptr);
  EXPECT_EQ(t.vector_size(v.data()), 2u);
  double x = 0;
  t.vector_get(v.data(), 1, &x);
  EXPECT_EQ(x, 2.5);
  const double y = 7.0;
  t.vector_set(v.data(), 0, &y);
  t.vector_push(v.data(), &y);
  EXPECT_EQ(v.as<std::vector<double>>(), (std::vector<double>{7.0, 2.5, 7.0}));

  // std::vector<bool> has no element addresses: access by copy serves it all the same.
  vsd::Value b(std::vector<bool>{true, false});
  bool e = false;
  b.type()->vector_get(b.data(), 0, &e);
  EXPECT_TRUE(e);
  b.type()->vector_set(b.data(), 1, &e);
  b.type()->vector_push(b.data(), &e);
  EXPECT_EQ(b.as<std::vector<bool>>(), (std::vector<bool>{true, true, true}));

  vsd::Value s(std::vector<std::string>{"a"});
  const std::string more = "b";
  s.type()->vector_push(s.data(), &more);
  std::string got;
  s.type()->vector_get(s.data(), 1, &got);
  EXPECT_EQ(got, "b");
}

TEST(VectorAccess, ServesRunTimeVectorsOfRunTimeEnumsAndStructs) {
  vsd::Registry reg;
  const vsd::MetaType& mode = vsd::EnumBuilder("AccessMode").value("Idle", 0).value("Busy", 5).define(reg);
  const vsd::MetaType& modes = reg.vector_type(mode);
  vsd::Value m(modes);
  ASSERT_NE(modes.ops().vector, nullptr);
  EXPECT_EQ(modes.vector_size(m.data()), 0u);
  vsd::Value busy(mode);
  mode.store_integer(busy.data(), 5);
  for (int i = 0; i < 9; ++i) modes.vector_push(m.data(), busy.data());  // past the first block of 4
  EXPECT_EQ(modes.vector_size(m.data()), 9u);
  vsd::Value idle(mode);
  modes.vector_set(m.data(), 8, idle.data());
  vsd::Value got(mode);
  modes.vector_get(m.data(), 3, got.data());
  EXPECT_EQ(mode.load_integer(got.data()), 5);
  modes.vector_get(m.data(), 8, got.data());
  EXPECT_EQ(mode.load_integer(got.data()), 0);
  EXPECT_EQ(m.to_text(), R"(["Busy", "Busy", "Busy", "Busy", "Busy", "Busy", "Busy", "Busy", "Idle"])");

  const vsd::MetaType& tag = vsd::StructBuilder("AccessTag")
                                 .field("label", vsd::meta_type<std::string>())
                                 .field("mode", mode)
                                 .define(reg);
  const vsd::MetaType& tags = reg.vector_type(tag);
  vsd::Value ts(tags);
  vsd::Value one = vsd::Value::from_text(tag, R"({"label": "first", "mode": "Busy"})");
  tags.vector_push(ts.data(), one.data());
  tags.vector_push(ts.data(), one.data());
  vsd::Value two = vsd::Value::from_text(tag, R"({"label": "second", "mode": "Idle"})");
  tags.vector_set(ts.data(), 1, two.data());
  vsd::Value back(tag);
  tags.vector_get(ts.data(), 1, back.data());
  EXPECT_EQ(back, two);
  EXPECT_EQ(ts, vsd::Value::from_text(tags, R"([{"label": "first", "mode": "Busy"},
                                               {"label": "second", "mode": "Idle"}])"));
}

TEST(VectorAccess, AnIndexOutOfRangeOrANonVectorIsAnError) {
  vsd::Value v(std::vector<std::int32_t>{1});
  std::int32_t x = 0;
  EXPECT_THAT([&] { v.type()->vector_get(v.data(), 1, &x); },
              ThrowsMessage<vsd::Error>(HasSubstr("vector<int32>: index 1 out of range (size 1)")));
  EXPECT_THAT([&] { v.type()->vector_set(v.data(), 5, &x); },
              ThrowsMessage<vsd::Error>(HasSubstr("index 5 out of range (size 1)")));
  vsd::Value d(2.0);
  EXPECT_THAT([&] { (void)d.type()->vector_size(d.data()); },
              ThrowsMessage<vsd::Error>(HasSubstr("type 'double' is not a vector")));
  EXPECT_EQ(d.type()->ops().vector, nullptr);
}

}  // namespace
