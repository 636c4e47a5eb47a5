/** @file
 *  @brief The Qt 5 twins of the benchmark fixture (compiled only when Qt5 Core is found; needs moc).
 *
 *  QtRobot is written the idiomatic Qt way: a Q_PROPERTY with READ/WRITE/NOTIFY whose setter emits the
 *  change signal when the value changes (the equivalent of a vsd property, which is observable too).
 */
#pragma once

#include <QObject>
#include <cstdint>

namespace bench {

class QtRobot : public QObject {
  Q_OBJECT
  Q_PROPERTY(double speed READ speed WRITE setSpeed NOTIFY speedChanged)
  Q_PROPERTY(double heading READ heading WRITE setHeading NOTIFY headingChanged)
  Q_PROPERTY(int battery READ battery WRITE setBattery NOTIFY batteryChanged)

 public:
  using QObject::QObject;

  double speed() const noexcept { return speed_; }
  void setSpeed(double v) {
    if (v == speed_) return;
    speed_ = v;
    Q_EMIT speedChanged(v);
  }
  double heading() const noexcept { return heading_; }
  void setHeading(double v) {
    if (v == heading_) return;
    heading_ = v;
    Q_EMIT headingChanged(v);
  }
  int battery() const noexcept { return battery_; }
  void setBattery(int v) {
    if (v == battery_) return;
    battery_ = v;
    Q_EMIT batteryChanged(v);
  }

 Q_SIGNALS:
  void speedChanged(double v);
  void headingChanged(double v);
  void batteryChanged(int v);

 private:
  double speed_ = 1.0;
  double heading_ = 0.0;
  int battery_ = 100;
};

/// Emits `ping(int)`.
class QtSender : public QObject {
  Q_OBJECT
 public:
  using QObject::QObject;
  void fire(int v) { Q_EMIT ping(v); }
 Q_SIGNALS:
  void ping(int v);
};

/// A receiver with its own state, connected through a pointer-to-member slot.
class QtReceiver : public QObject {
  Q_OBJECT
 public:
  using QObject::QObject;
  std::uint64_t calls = 0;
  std::int64_t sum = 0;
 public Q_SLOTS:
  void onPing(int v) {
    ++calls;
    sum += v;
  }
};

}  // namespace bench
