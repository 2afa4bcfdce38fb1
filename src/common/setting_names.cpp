#include "cartpole_qlearning/common/setting_names.h"

namespace cartpole_qlearning
{
std::string SettingNames::operator()(Setting setting) const
{
  return namer_ ? namer_(setting) : plainSettingName(setting);
}

std::string plainSettingName(Setting setting)
{
  switch (setting)
  {
    case Setting::LoadOnStart:
      return "the table to start from";
    case Setting::LoadOnStartOrigin:
      return "";
    case Setting::TablePath:
      return "the default table";
    case Setting::TableFolder:
      return "the table folder";
    case Setting::SaveService:
      return "";
    case Setting::StatsCsv:
      return "the learning curve's file";
    case Setting::Seed:
      return "the seed";
    case Setting::StartRegion:
      return "the start region";
    case Setting::ResetService:
      return "the reset service";
    case Setting::ResetServiceType:
      return "the reset service's type";
    case Setting::DecisionPeriod:
      return "the decision period";
    case Setting::StateTopic:
      return "the state topic";
    case Setting::CommandTimeout:
      return "the timeout";
    case Setting::CurveViewer:
      return "a plot of";
    case Setting::SuiteEvaluation:
      return "an evaluation of the table by the suite";
  }
  return "a setting";
}

}  // namespace cartpole_qlearning
