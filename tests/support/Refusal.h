// Refusals in both builds (quathinge/btQuaternionHingeErrors.h): with exceptions a refused call throws
// std::invalid_argument; built with QUATHINGE_EXCEPTIONS=OFF it reports through the error callback and returns.
// These helpers expect the one or the other, so every bad-input test runs in both builds.
#ifndef QUATHINGE_TESTS_REFUSAL_H
#define QUATHINGE_TESTS_REFUSAL_H

#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace qh_test
{
/// Whether refusals throw in this build.
#ifdef QUATHINGE_NO_EXCEPTIONS
constexpr bool kExceptions = false;
#else
constexpr bool kExceptions = true;
#endif

/// `call` was refused once, with a message naming `parameter`.
::testing::AssertionResult refused(const std::function<void()>& call, const std::string& parameter);
/// `call` was accepted: nothing thrown, nothing reported.
::testing::AssertionResult accepted(const std::function<void()>& call);

/// Captures every report made through the error callback while it lives (the previous callback is restored after).
class ErrorCapture
{
public:
	ErrorCapture();
	~ErrorCapture();
	ErrorCapture(const ErrorCapture&) = delete;
	ErrorCapture& operator=(const ErrorCapture&) = delete;
	int count = 0;
	std::string first;

private:
	void* m_previousUser = nullptr;
	void (*m_previous)(const char*, void*) = nullptr;
};
}  // namespace qh_test

#define EXPECT_REFUSED(statement, parameter) EXPECT_TRUE(::qh_test::refused([&] { statement; }, parameter))
#define EXPECT_ACCEPTED(statement) EXPECT_TRUE(::qh_test::accepted([&] { statement; }))

#endif
