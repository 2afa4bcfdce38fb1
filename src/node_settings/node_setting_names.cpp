#include "cartpole_qlearning/node_settings/node_setting_names.h"

namespace cartpole_qlearning
{
namespace
{
std::string nodeName(Setting setting)
{
  switch (setting)
  {
    case Setting::LoadOnStart:
      return "~load_on_start";
    case Setting::LoadOnStartOrigin:
      return "~load_on_start, which the launch files' q_table or load argument sets";
    case Setting::TablePath:
      return "~q_table_path";
    case Setting::TableFolder:
      return "~q_table_dir";
    case Setting::SaveService:
      return "~save_q_table";
    case Setting::StatsCsv:
      return "~stats_csv";
    case Setting::Seed:
      return "~seed";
    case Setting::StartRegion:
      return "~start_region";
    case Setting::ResetService:
      return "~reset_service";
    case Setting::ResetServiceType:
      return "~reset_service_type";
    case Setting::DecisionPeriod:
      return "~decision_period";
    case Setting::StateTopic:
      return "~state_topic (robot.launch joint_states:=)";
    case Setting::CommandTimeout:
      return "~timeout";
    case Setting::CurveViewer:
      return "rosrun cartpole_qlearning plot_learning_curve --follow";
    case Setting::SuiteEvaluation:
      return "train_headless --evaluate TABLE --suite FILE";
  }
  return plainSettingName(setting);
}
}  // namespace

SettingNames nodeSettingNames()
{
  return SettingNames(nodeName);
}

std::string nodeParameterName(Setting setting)
{
  const std::string name = nodeName(setting);
  if (name.size() < 2 || name.front() != '~')
    return "";
  const std::size_t end = name.find_first_of(" ,");
  return name.substr(1, end == std::string::npos ? std::string::npos : end - 1);
}

}  // namespace cartpole_qlearning
