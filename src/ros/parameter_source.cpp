#include "parameter_source.h"

#include "cartpole_qlearning/ros/conversions.h"

#include <ros/names.h>
#include <ros/package.h>

#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdlib>

namespace cartpole_qlearning
{
namespace
{
using XmlRpc::XmlRpcValue;

bool isNumber(XmlRpcValue& v)
{
  return v.getType() == XmlRpcValue::TypeDouble || v.getType() == XmlRpcValue::TypeInt;
}

double toDouble(XmlRpcValue& v)
{
  return v.getType() == XmlRpcValue::TypeInt ? static_cast<int>(v) : static_cast<double>(v);
}

void collect(XmlRpcValue& value, const std::string& prefix, std::vector<std::string>& keys)
{
  if (value.getType() != XmlRpcValue::TypeStruct)
  {
    keys.push_back(prefix);
    return;
  }
  for (auto& entry : value)
    collect(entry.second, (prefix.empty() ? "" : prefix + "/") + entry.first, keys);
}
}  // namespace

void refuseParameter(const ros::NodeHandle& nh, const std::string& name, const std::string& value,
                     const std::string& allowed)
{
  throw ConfigError("parameter " + nh.resolveName(name) + " = " + value + " is not allowed (" + allowed + ")");
}

std::string RosParameterSource::origin() const
{
  return "parameter server (" + nh_.getNamespace() + ")";
}

std::string RosParameterSource::describe(const std::string& key) const
{
  return "parameter " + nh_.resolveName(key);
}

std::string RosParameterSource::folder() const
{
  std::string path;
  if (!nh_.getParam("config_file", path) || path.empty())
    return "";
  return configFolder(path);
}

bool RosParameterSource::get(const std::string& key, double& value) const
{
  XmlRpcValue v;
  if (!nh_.getParam(key, v))
    return false;
  if (!isNumber(v))
    throw ConfigError(describe(key) + " = '" + v.toXml() + "' is not allowed (must be a number)");
  value = toDouble(v);
  return true;
}

bool RosParameterSource::get(const std::string& key, std::int64_t& value) const
{
  XmlRpcValue v;
  if (!nh_.getParam(key, v))
    return false;
  if (v.getType() != XmlRpcValue::TypeInt)
    throw ConfigError(describe(key) + " = '" + v.toXml() + "' is not allowed (must be a whole number)");
  value = static_cast<int>(v);
  return true;
}

bool RosParameterSource::get(const std::string& key, bool& value) const
{
  XmlRpcValue v;
  if (!nh_.getParam(key, v))
    return false;
  if (v.getType() != XmlRpcValue::TypeBoolean)
    throw ConfigError(describe(key) + " = '" + v.toXml() + "' is not allowed (must be true or false)");
  value = static_cast<bool>(v);
  return true;
}

bool RosParameterSource::get(const std::string& key, std::string& value) const
{
  XmlRpcValue v;
  if (!nh_.getParam(key, v))
    return false;
  if (v.getType() != XmlRpcValue::TypeString)
    throw ConfigError(describe(key) + " = '" + v.toXml() + "' is not allowed (must be a string)");
  value = static_cast<std::string>(v);
  return true;
}

bool RosParameterSource::get(const std::string& key, std::vector<double>& value) const
{
  XmlRpcValue v;
  if (!nh_.getParam(key, v))
    return false;
  if (v.getType() != XmlRpcValue::TypeArray)
    throw ConfigError(describe(key) + " must be a list of numbers");
  value.clear();
  for (int i = 0; i < v.size(); ++i)
  {
    if (!isNumber(v[i]))
      throw ConfigError(describe(key) + "[" + std::to_string(i) + "] = '" + v[i].toXml() +
                        "' is not allowed (must be a number)");
    value.push_back(toDouble(v[i]));
  }
  return true;
}

bool RosParameterSource::get(const std::string& key, std::vector<std::string>& value) const
{
  XmlRpcValue v;
  if (!nh_.getParam(key, v))
    return false;
  if (v.getType() != XmlRpcValue::TypeArray)
    throw ConfigError(describe(key) + " must be a list of strings");
  value.clear();
  for (int i = 0; i < v.size(); ++i)
  {
    if (v[i].getType() != XmlRpcValue::TypeString)
      throw ConfigError(describe(key) + "[" + std::to_string(i) + "] = '" + v[i].toXml() +
                        "' is not allowed (must be a string)");
    value.push_back(static_cast<std::string>(v[i]));
  }
  return true;
}

std::vector<std::string> RosParameterSource::keysUnder(const std::string& section) const
{
  std::vector<std::string> keys;
  XmlRpcValue v;
  // An empty section: every parameter in the node handle's namespace.
  if (nh_.getParam(section.empty() ? nh_.getNamespace() : section, v))
    collect(v, section, keys);
  return keys;
}

ControllerSettings readControllerParameters(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                            bool shutdown_by_default)
{
  ControllerContext context;
  context.name_space = nh.getNamespace();
  const char* home = std::getenv("HOME");
  context.home = home ? home : "";
  context.shutdown_by_default = shutdown_by_default;
  context.name_error = [](const std::string& name) {
    std::string error;
    return ros::names::validate(name, error) ? std::string() : error;
  };
  // Live tuning's values, which the controller's dynamic_reconfigure server keeps there.
  context.other_keys = learningConfigKeys();
  context.suite_folders = {ros::package::getPath("cartpole_qlearning") + "/config"};
  return readControllerSettings(RosParameterSource(nh), RosParameterSource(pnh), context);
}

}  // namespace cartpole_qlearning
