#include "support/CallerReplay.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace qh_test
{
double maxAngleDiff(const std::vector<double>& a, const std::vector<double>& b)
{
	EXPECT_EQ(a.size(), b.size());
	double worst = 0;
	for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::fabs(angleDiff(a[i], b[i])));
	return worst;
}

double unwrapped(const std::vector<double>& angles)
{
	if (angles.empty()) return 0;
	double total = angles[0];
	for (size_t i = 1; i < angles.size(); ++i) total += angleDiff(angles[i], angles[i - 1]);
	return total;
}

void expectSameRun(const char* name, const CallerRun& stock, const CallerRun& quat, double angleTol, double readTol)
{
	EXPECT_TRUE(stock.finite) << name;
	EXPECT_TRUE(quat.finite) << name;
	ASSERT_EQ(stock.reads.size(), quat.reads.size()) << name;
	for (size_t i = 0; i < stock.reads.size(); ++i)
	{
		if (readTol == 0) EXPECT_EQ(quat.reads[i], stock.reads[i]) << name << ": read " << i;
		else EXPECT_NEAR(quat.reads[i], stock.reads[i], readTol) << name << ": read " << i;
	}
	const double diff = maxAngleDiff(stock.angles, quat.angles);
	if (std::getenv("QUATHINGE_CALLER_TRACE"))  // both angle traces, step by step, for a closer look
		for (size_t i = 0; i < std::min(stock.angles.size(), quat.angles.size()); ++i)
			std::printf("%s %zu %.6f %.6f\n", name, i, stock.angles[i], quat.angles[i]);
	std::printf(
		"[ figures  ] %s: %zu steps, hinge angle apart by at most %.3g rad; final stock %.4f, quaternion %.4f "
		"rad; pivots apart at most stock %.2g m, quaternion %.2g m\n",
		name, stock.angles.size(), diff, stock.angles.empty() ? 0.0 : stock.angles.back(),
		quat.angles.empty() ? 0.0 : quat.angles.back(), stock.maxSeparation, quat.maxSeparation);
	EXPECT_LE(diff, angleTol) << name;
}
}  // namespace qh_test
